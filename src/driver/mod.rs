//! The MPM time step (paper eqs. (13)–(31), thesis Fig. 2.5), generic over the
//! basis, the mass strategy and the material. Nothing here knows which basis it has.
//!
//! [`Driver::step`] is the ordered list of the [`phases`]:
//! 1. locate every particle (walking from its previous element) and evaluate the basis;
//! 2. assemble `M` (eq. (13)), `F^int` (eq. (15)) and the effects' forces (eqs. (14), (16));
//! 3. solve `M a = F` (eq. (17)) with the walls (strategy solve, then the general
//!    constraints);
//! 4. update particle velocities `v_p += Δt Σ a_i phi_i(x_p)` (eq. (18)) and scatter
//!    their momentum `P` (eq. (21));
//! 5. project velocities `M v̂ = P` (eq. (20));
//! 6. update `F_p ← (I + Δt ∇v_p) F_p` with the full velocity gradient, `σ_p`,
//!    `V_p = J_p V_p⁰` (eqs. (22)–(29)), and move particles
//!    `x_p += Δt Σ v̂_i phi_i(x_p)`, `u_p` likewise (eqs. (30)–(31)).
//!
//! The paper (eq. (24)) updates `F` with the symmetric part of the velocity gradient,
//! which ignores rotation: a rigidly rotating body would accumulate spurious strain.
//! We use the full gradient `∇v` (see [`phases::update_deformation_gradient`]).
//!
//! All buffers are allocated once in [`Driver::new`]; a step allocates nothing.
//!
//! The particle phases run on the current rayon thread pool (run the loop inside
//! [`rayon::ThreadPool::install`] to choose the threads, or see
//! [`crate::threads`]); results are bit-identical for any number of threads (see
//! [`phases`]).

mod binning;
mod critical;
mod energy;
mod failure;
pub mod phases;

pub use critical::{
    WatchReport, ADVECTION_SHARE, CONTACT_SHARE, CRITICAL_ITERATIONS, MAX_SUBSTEPS, WATCH_EVERY,
    WATCH_ITERATIONS, WATCH_SEED_SHARE,
};
pub(crate) use failure::point;
pub(crate) use failure::triangle_aspect;
pub use failure::{BodySampling, SetupError, StepError, NEARLY_SINGULAR, SLIVER_ASPECT};

pub use crate::diagnostics::{PhaseTimes, StepReport};
pub use phases::update_deformation_gradient;

use crate::diagnostics::TERMS;
use crate::effect::{Effect, ParticleBasis, StepState};
use crate::mass::{
    Constraints, Correction, MassReport, MassSetup, MassStrategy, Needs, StepContext, SupportFacts,
};
use crate::materials::ParticleMaterials;
use crate::particles::Particles;
use crate::sparse::{Scalar, SymmetricPattern};
use nalgebra::{SMatrix, SVector};
use phases::{Bins, Evaluations, Gather, Local, UpdateFailure};
use psmpm_basis::{Basis, BasisEval};
use rayon::prelude::*;
use std::time::Instant;

/// Coverage below which a function counts as under-supported in failure messages.
pub const UNDER_SUPPORTED_COVERAGE: f64 = 0.1;

/// A particle that starts closer to a contact wall than this share of its contact
/// distance (half its spacing) was placed in the wall's contact layer: its spring
/// has that little room (`contact::ContactWall`). A block placed with a corner
/// on a 40° contact slope, the contact distance 0.0125, its nearest particle
/// 6.9e-5 from the slope, went through it at step 15 at `courant = 0.5` (step 101
/// at 0.25); 5.2e-4 from it, at step 298 (it held at 0.25); 1.0e-3 from it and
/// more, it slid down at both.
pub const STARTED_CLOSE: f64 = 0.1;

/// A homogeneous Dirichlet condition: velocity component `component` vanishes on `tag`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Fix {
    /// Boundary tag.
    pub tag: String,
    /// Velocity component (0 = x, 1 = y).
    pub component: usize,
}

/// The per-step facts a mass strategy asked for.
struct StrategyInputs {
    needs: Needs,
    touches_empty: Vec<bool>,
    particle_volume: Vec<f64>,
    particle_count: Vec<f64>,
    /// `on_wall[i]`: a wall constrains function `i` (a fixed component or a
    /// general constraint's term); sized with the coverage.
    on_wall: Vec<bool>,
    support: Option<std::sync::Arc<SupportFacts>>,
    /// Particles on the edges and vertices of elements other than their own,
    /// when a decision depends on which elements hold particles (empty elements,
    /// live functions, the affine-preserving lumping); refilled every step.
    touching: Option<phases::Touching>,
    /// `touching` holds this step's particles. Left stale in a step in which
    /// every element holds a particle: the live functions and the empty elements
    /// read it only for the elements without one, so only the affine-preserving
    /// lumping needs it then, and fills it ([`StrategyInputs::fill_touching`]).
    touching_current: bool,
    /// `live[i]`: an element holding a particle, or with one on its closure, has
    /// function `i` (with `touching`; else the gather's live functions serve).
    live: Vec<bool>,
    /// The true entries of `live`, ascending, when the gather runs through its
    /// live list (`live_listed`).
    live_list: Vec<u32>,
    live_listed: bool,
    /// Scratch of [`phases::add_affine_lumping`], one per element.
    element_affine: phases::AffineMarks,
    /// Scratch of [`phases::add_affine_lumping`], one per function.
    function_pinned: Vec<bool>,
    /// [`StepContext::flat`], one per function (the default with a basis of
    /// degree 2; else empty).
    flat: Vec<bool>,
}

impl StrategyInputs {
    /// Fills `touching` and `live` for the particles binned in `bins`.
    fn mark_touching<T: Scalar, const D: usize, B: Basis<T, D>>(
        &mut self,
        basis: &B,
        particles: &Particles<T, D>,
        bins: &Bins,
        gather: &Gather,
    ) {
        self.touching_current = false;
        if self.touching.is_none() {
            return;
        }
        self.live.clear();
        self.live.extend_from_slice(gather.live());
        let listed = gather.live_list();
        self.live_listed = listed.is_some();
        if let Some(list) = listed {
            self.live_list.clear();
            self.live_list.extend_from_slice(list);
        }
        // Every element holds a particle: nothing more is live, nothing empty.
        if (0..basis.num_elements()).all(|e| bins.occupied(e)) {
            return;
        }
        self.fill_touching(basis, particles);
        let touching = self.touching.as_ref().expect("checked above");
        if touching.is_empty() {
            return;
        }
        for e in 0..basis.num_elements() {
            if !bins.occupied(e) && touching.occupied(bins, e) {
                for &i in basis.element_functions(e) {
                    if !self.live[i] && self.live_listed {
                        self.live_list.push(i as u32);
                    }
                    self.live[i] = true;
                }
            }
        }
        if self.live_listed {
            self.live_list.sort_unstable();
        }
    }

    /// The true entries of `live`, ascending, when the gather runs through its
    /// live list.
    fn live_list(&self) -> Option<&[u32]> {
        self.live_listed.then_some(&self.live_list[..])
    }

    /// Fills `touching` for this step's particles, unless it holds them already
    /// (once per step at most; nothing without `touching`).
    fn fill_touching<T: Scalar, const D: usize, B: Basis<T, D>>(
        &mut self,
        basis: &B,
        particles: &Particles<T, D>,
    ) {
        if let Some(touching) = self.touching.as_mut() {
            if !self.touching_current {
                touching.fill(basis, &particles.x, &particles.element);
                self.touching_current = true;
            }
        }
    }
}

/// The MPM driver.
pub struct Driver<T, const D: usize, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: ParticleMaterials<T, D>,
{
    /// The basis.
    pub basis: B,
    /// The particles.
    pub particles: Particles<T, D>,
    material: Mat,
    mass: M,
    /// `walled[i]`: a wall (`fix`) constrains function `i`, for the message of a
    /// particle that leaves the mesh through a wall.
    walled: Vec<bool>,
    /// The functions and position of each vertex where two slip walls meet at a
    /// bend ([`Driver::average_slip_bends`]), for the message of a particle that
    /// leaves the mesh there.
    slip_bends: Vec<(Vec<usize>, Vec<f64>)>,
    /// `fixed[k][i]`: component `k` of function `i` is held at zero (`fix`).
    fixed: Vec<Vec<bool>>,
    /// Each element's width, its smallest altitude (the advection limit of the
    /// watch, [`Driver::watch_critical_step`]).
    element_width: Vec<f64>,
    /// The largest particle speed at the start (the scene's own speeds, which a
    /// blow-up's are not).
    initial_speed: f64,
    constraints: Constraints<T, D>,
    effects: Vec<Box<dyn Effect<T, D>>>,
    pattern: SymmetricPattern,
    /// The step being taken: `dt_outer`, or a sub-step of it
    /// ([`Driver::watch_critical_step`]).
    dt: T,
    /// The time step of [`Driver::step`].
    dt_outer: f64,
    step: usize,
    time: f64,
    /// The watch over the critical step while the bodies move, when enabled.
    watch: Option<critical::Watch<T>>,
    /// The last vector of the power iteration of [`Driver::critical_time_step`].
    critical_vector: Vec<Vec<T>>,
    // Buffers, sized once.
    evals: Evaluations<T, D>,
    /// One basis scratch per particle chunk ([`phases::CHUNK`]).
    scratch: Vec<BasisEval<T, D>>,
    /// Particles by element, every step.
    bins: Bins,
    /// Element-local sums.
    local: Local<T, D>,
    /// Element-local sums → matrix entries and coefficients.
    gather: Gather,
    values: Vec<T>,
    /// `F`, then the acceleration coefficients `a`.
    rhs: Vec<Vec<T>>,
    /// `P`, then the projected velocity coefficients `v̂`.
    velocity: Vec<Vec<T>>,
    /// `v̂ⁿ` is known (after the first step, or after projecting the initial state).
    velocity_known: bool,
    /// Forces of the non-conservative effects (for their work); empty without any.
    work_force: Vec<Vec<T>>,
    /// Forces of the dissipative effects ([`Effect::dissipative`]), a part of
    /// `work_force`; empty without any.
    dissipative_force: Vec<Vec<T>>,
    /// Scratch for [`Effect::adjust_forces`]; empty without effects.
    adjust: Vec<Vec<T>>,
    /// Per-particle forces of the effects that act per particle
    /// ([`Effect::particle_force`]); empty without any.
    particle_force: Vec<SVector<T, D>>,
    /// `Σ_p phi_i(x_p) f_p` of the effects that act per particle and do no work,
    /// summed in phase 2a's pass over the particles; empty without any.
    body_force: Vec<Vec<T>>,
    /// `C_p` of the affine correction ([`phases::Affine`]); empty unless the
    /// strategy asks for it.
    affine_gradient: Vec<SMatrix<T, D, D>>,
    /// The points of linear precision `ξ_i`; empty unless the strategy asks for
    /// the affine correction.
    function_points: Vec<SVector<T, D>>,
    /// The size of each element for the affine-preserving lumping
    /// ([`phases::element_scales`]); empty unless the strategy uses it.
    element_scale: Vec<T>,
    /// The basis's functions are affine on every element (degree 1): the
    /// affine-preserving lumping keeps only its plain share there
    /// ([`phases::add_affine_lumping`]).
    functions_affine: bool,
    /// Per-chunk sums of the particle terms of the step report's energies
    /// (written by [`phases::update_particles`]).
    energy_terms: Vec<[f64; TERMS]>,
    /// The end (one past the last particle) of each body's particles, the bodies
    /// stored one after another ([`Driver::set_body_sizes`]); empty for one body.
    body_ends: Vec<usize>,
    /// The particles' changes of element over the run (one per particle and
    /// location that found another element than the last; phase 1).
    element_changes: u64,
    /// Per-chunk sums `Σ_p m_p v_pⁿ · Δv_p` of the velocity update (phase 4), for
    /// the time-centred kinetic energy.
    centred_terms: Vec<f64>,
    /// `(K, S + P − W)` of the state at the start of the step: the last report's,
    /// or the initial state's before the first step.
    previous_energy: Option<(f64, f64)>,
    work: f64,
    /// `½ Δt F⁰ · v̂⁰` of the first step: the share of the start power the
    /// time-centred total's work does not count ([`Driver::step`]).
    first_half_power: Option<f64>,
    /// The part of `work` done by the dissipative effects ([`Effect::dissipative`]).
    dissipated: f64,
    inputs: StrategyInputs,
    last_report: MassReport,
    last_condition: Option<f64>,
    phases: PhaseTimes,
    /// The critical time step, once estimated ([`Driver::critical_time_step`]).
    dt_critical: Option<f64>,
    /// Estimate the condition number every step.
    pub estimate_condition: bool,
}

impl<T, const D: usize, B, M, Mat> Driver<T, D, B, M, Mat>
where
    T: Scalar,
    B: Basis<T, D>,
    M: MassStrategy<T>,
    Mat: ParticleMaterials<T, D>,
{
    /// Sets up a run: the mass strategy's symbolic work and the basis facts it
    /// asks for, Dirichlet sets, particle location, initial stress from the
    /// initial deformation gradients.
    pub fn new(
        basis: B,
        mut particles: Particles<T, D>,
        material: Mat,
        mut mass: M,
        fixes: &[Fix],
        mut effects: Vec<Box<dyn Effect<T, D>>>,
        dt: f64,
    ) -> Result<Self, SetupError> {
        for effect in &mut effects {
            effect.set_time_step(dt);
        }
        let n = basis.num_functions();
        // Function indices, pattern positions and local offsets are stored in 32
        // bits: below 2³¹ functions and local entries, the pattern's entries
        // (at most the local ones plus the diagonal) stay below 2³².
        let local_entries = basis
            .num_elements()
            .checked_mul(basis.max_functions_per_element().pow(2));
        if n >= 1 << 31 || local_entries.is_none_or(|l| l >= 1 << 31) {
            return Err(SetupError::TooManyFunctions {
                functions: n,
                elements: basis.num_elements(),
            });
        }
        if u32::try_from(particles.len()).is_err() {
            return Err(SetupError::TooManyParticles {
                particles: particles.len(),
            });
        }
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
            for c in basis.dirichlet(&fix.tag, &direction)? {
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
                        position: to_f64(&particles.x[p]),
                    })
                }
            }
            particles.sigma[p] = particles.initial_stress(p) + material.stress(p, &particles.f[p]);
        }
        let scratch = |needed: bool| {
            if needed {
                vec![vec![T::zero(); n]; D]
            } else {
                Vec::new()
            }
        };
        let pattern = SymmetricPattern::new(&basis);
        let needs = mass.needs();
        let support = (needs.coverage || needs.polynomials)
            .then(|| std::sync::Arc::new(SupportFacts::new(&basis, &pattern, needs.polynomials)));
        mass.prepare(&MassSetup {
            pattern: &pattern,
            fixed: &fixed,
            support: support.as_ref(),
        });
        let walled = on_wall(n, &fixed, &general);
        let inputs = StrategyInputs {
            needs,
            touches_empty: vec![false; if needs.empty_elements { n } else { 0 }],
            particle_volume: vec![0.0; if needs.coverage { n } else { 0 }],
            particle_count: vec![0.0; if needs.coverage { n } else { 0 }],
            on_wall: if needs.coverage {
                walled.clone()
            } else {
                Vec::new()
            },
            support,
            touching: (needs.empty_elements
                || needs.coverage
                || needs.correction == Correction::InMass)
                .then(phases::Touching::default),
            touching_current: false,
            live: Vec::new(),
            live_list: Vec::new(),
            live_listed: false,
            element_affine: if needs.correction == Correction::InMass {
                phases::AffineMarks::new(basis.num_elements())
            } else {
                phases::AffineMarks::default()
            },
            function_pinned: if needs.correction == Correction::InMass {
                vec![false; basis.num_functions()]
            } else {
                Vec::new()
            },
            flat: if needs.correction == Correction::InMass && basis.degree() > 1 {
                vec![false; basis.num_functions()]
            } else {
                Vec::new()
            },
        };
        let np = particles.len();
        let stride = basis.max_functions_per_element();
        let corrects = needs.correction != Correction::None;
        let function_points: Vec<SVector<T, D>> = if corrects {
            (0..n)
                .map(|i| SVector::from_fn(|k, _| T::of(basis.function_point(i)[k])))
                .collect()
        } else {
            Vec::new()
        };
        let element_scale = if needs.correction == Correction::InMass {
            phases::element_scales(&basis, &function_points)
        } else {
            Vec::new()
        };
        let momentum_corrects = matches!(needs.correction, Correction::Rigid | Correction::Affine);
        let fused_body_forces = effects
            .iter()
            .any(|e| e.acts_per_particle() && !e.does_work());
        Ok(Driver {
            scratch: (0..phases::chunks(np))
                .map(|_| BasisEval::for_basis(&basis))
                .collect(),
            evals: Evaluations::for_basis(&basis, np),
            bins: Bins::new(basis.num_elements(), np),
            local: {
                let local = Local::new(basis.num_elements(), stride);
                let local = if needs.coverage {
                    local.with_coverage()
                } else {
                    local
                };
                if fused_body_forces {
                    local.with_body_forces()
                } else {
                    local
                }
            },
            gather: Gather::new(&basis, &pattern, stride),
            values: vec![T::zero(); pattern.nnz()],
            rhs: vec![vec![T::zero(); n]; D],
            velocity: vec![vec![T::zero(); n]; D],
            velocity_known: false,
            work_force: scratch(effects.iter().any(|e| e.does_work())),
            dissipative_force: scratch(effects.iter().any(|e| e.does_work() && e.dissipative())),
            adjust: scratch(!effects.is_empty()),
            energy_terms: vec![[0.0; TERMS]; phases::chunks(np)],
            body_ends: Vec::new(),
            centred_terms: vec![0.0; phases::chunks(np)],
            element_changes: 0,
            previous_energy: None,
            affine_gradient: vec![SMatrix::zeros(); if momentum_corrects { np } else { 0 }],
            function_points,
            element_scale,
            functions_affine: basis.degree() == 1,
            particle_force: if effects.iter().any(|e| e.acts_per_particle()) {
                vec![SVector::zeros(); np]
            } else {
                Vec::new()
            },
            body_force: scratch(fused_body_forces),
            work: 0.0,
            first_half_power: None,
            dissipated: 0.0,
            constraints: Constraints::new(general, n),
            walled,
            slip_bends: Vec::new(),
            fixed,
            element_width: critical::element_widths(&basis),
            initial_speed: particles
                .v
                .iter()
                .map(|v| v.norm().to_f64())
                .fold(0.0, f64::max),
            inputs,
            last_condition: None,
            phases: PhaseTimes::default(),
            dt_critical: None,
            estimate_condition: false,
            basis,
            particles,
            material,
            mass,
            effects,
            pattern,
            dt: T::of(dt),
            dt_outer: dt,
            step: 0,
            time: 0.0,
            watch: None,
            critical_vector: Vec::new(),
            last_report: MassReport::default(),
        })
    }

    /// Adds a slip wall: the velocity component along the unit vector `normal`
    /// vanishes on the boundary tagged `tag` (for an oblique straight wall, its
    /// normal). The constraints couple the components of each coefficient and are
    /// imposed exactly by projection in the mass-matrix norm (see [`Constraints`]).
    /// A wall whose normal lies along an axis is better given to [`Driver::new`] as a
    /// [`Fix`] of that component, as the scene set-up does: the same constrained
    /// solution, eliminated from the system instead of projected, and the
    /// projection onto the extension's reduced system gained energy at impacts
    /// (`docs/stability.md`, "Slip walls along an axis").
    pub fn add_slip_wall(&mut self, tag: &str, normal: &SVector<T, D>) -> Result<(), SetupError> {
        let constraints = self.basis.dirichlet(tag, normal)?;
        let mut general = std::mem::take(&mut self.constraints.rows);
        for c in constraints {
            general.push(expand_row(&c.terms, normal));
        }
        if !self.inputs.on_wall.is_empty() {
            mark_terms(&mut self.inputs.on_wall, &general);
        }
        mark_terms(&mut self.walled, &general);
        self.constraints = Constraints::new(general, self.basis.num_functions());
        Ok(())
    }

    /// Slip walls meeting at a bend share the bend's vertex through their mean
    /// normal. Each wall holds, at each vertex of its edges, the value of the
    /// velocity along its normal and that value's derivative along the wall (paper
    /// §2.3's Dirichlet conditions for PS, `ps-splines.md` §5; the value alone for
    /// PL). At a vertex shared by two walls at a bend the value is then held along
    /// two directions, so the vertex holds still and a body sliding over the bend
    /// strikes it (a block sliding from a 21.8° slope onto a 16.7° one stopped
    /// there and slid back). Here the two value rows become one along the mean
    /// normal `n̄ = (n_a + n_b) / |n_a + n_b|`, and each wall keeps its own
    /// derivative row: the vertex moves along the mean tangent, and near it each
    /// wall lets through `sin(θ/2)` of that velocity across itself (4.4 % at a 5°
    /// bend). Call after [`Driver::add_slip_wall`] for the oblique walls, with the
    /// bends to share (the scene set-up passes those up to 22.5°,
    /// `setup::mesh::SLIP_BEND_SHARED`) between two slip walls (those along an axis included: the component
    /// their [`Fix`] held at the vertex is released). Returns the number of bends
    /// treated; a bend at a vertex a no-slip wall also holds is left as it is.
    pub fn average_slip_bends(&mut self, bends: &[SlipBend<T, D>]) -> Result<usize, SetupError> {
        let n = self.basis.num_functions();
        let mut rows = std::mem::take(&mut self.constraints.rows);
        let (mut treated, mut unfixed) = (0, false);
        let mut at = BasisEval::for_basis(&self.basis);
        for bend in bends {
            let [na, nb] = bend.normals;
            let sum = na + nb;
            let mean = sum / T::of(sum.norm().to_f64());
            // The basis at the vertex, from just inside the domain (a vertex on the
            // boundary may fall outside every element by round-off).
            let scale = 1.0
                + bend
                    .vertex
                    .iter()
                    .map(|x| x.to_f64().abs())
                    .fold(0.0, f64::max);
            let inside = bend.vertex - mean * T::of(1e-10 * scale);
            let Some(e) = self
                .basis
                .locate(&bend.vertex, None)
                .or_else(|| self.basis.locate(&inside, None))
            else {
                continue;
            };
            self.basis.eval(e, &bend.vertex, &mut at);
            let m = at.len();
            let size = (0..m).map(|q| at.phi[q].to_f64().abs()).fold(0.0, f64::max);
            // The functions of the vertex: those with a value or a gradient there.
            let tiny = 1e-12;
            let of_vertex: Vec<usize> = (0..m)
                .filter(|&q| {
                    at.phi[q].to_f64().abs() > tiny * size
                        || at.grad_phi[q]
                            .iter()
                            .any(|g| g.to_f64().abs() > tiny * size)
                })
                .collect();
            let functions: Vec<usize> = of_vertex.iter().map(|&q| at.index[q]).collect();
            // Each wall's rows at the vertex: those on the vertex's functions alone.
            let mut held = Vec::new();
            for (tag, normal) in bend.tags.iter().zip([na, nb]) {
                for c in self.basis.dirichlet(tag, &normal)? {
                    if c.terms.iter().all(|(i, _)| functions.contains(i)) {
                        held.push((c, normal));
                    }
                }
            }
            // A function held in every component (a no-slip wall there): leave it.
            if functions.iter().any(|&i| (0..D).all(|k| self.fixed[k][i])) {
                continue;
            }
            for (c, normal) in &held {
                match (single_axis(normal), c.is_single()) {
                    (Some(k), true) => {
                        self.fixed[k][c.terms[0].0] = false;
                        unfixed = true;
                    }
                    (axis, _) => {
                        // An axis wall's rows were made along the positive axis
                        // ([`Driver::new`]), an oblique wall's along its normal.
                        let along = axis.map_or(*normal, |k| {
                            let mut e = SVector::<T, D>::zeros();
                            e[k] = T::one();
                            e
                        });
                        let row = expand_row(&c.terms, &along);
                        rows.retain(|r| *r != row);
                    }
                }
            }
            // The value along the mean normal; the derivative along each wall, along
            // its own normal (PS: a C¹ basis holds the tangential derivative too).
            let value: Vec<(usize, T)> = of_vertex
                .iter()
                .map(|&q| (at.index[q], at.phi[q]))
                .collect();
            rows.push(expand_row(&value, &mean));
            if self.basis.degree() > 1 && D == 2 {
                for normal in [na, nb] {
                    let mut tangent = SVector::<T, D>::zeros();
                    tangent[0] = -normal[1];
                    tangent[1] = normal[0];
                    let derivative: Vec<(usize, T)> = of_vertex
                        .iter()
                        .map(|&q| (at.index[q], at.grad_phi[q].dot(&tangent)))
                        .collect();
                    rows.push(expand_row(&derivative, &normal));
                }
            }
            self.slip_bends.push((functions, to_f64(&bend.vertex)));
            treated += 1;
        }
        if !self.inputs.on_wall.is_empty() {
            mark_terms(&mut self.inputs.on_wall, &rows);
        }
        mark_terms(&mut self.walled, &rows);
        self.constraints = Constraints::new(rows, n);
        if unfixed {
            self.mass.prepare(&MassSetup {
                pattern: &self.pattern,
                fixed: &self.fixed,
                support: self.inputs.support.as_ref(),
            });
        }
        Ok(treated)
    }

    /// Tells the driver which particles make up each body: `sizes[b]` particles of
    /// body `b`, following those of the bodies before it. The step report's
    /// translational energy ([`StepReport::translational`]) is then that of each
    /// body's translation, summed; without it (or with sizes that do not add up to
    /// the number of particles, which are ignored) the particles are one body.
    pub fn set_body_sizes(&mut self, sizes: &[usize]) {
        self.body_ends.clear();
        if sizes.len() > 1 && sizes.iter().sum::<usize>() == self.particles.len() {
            let mut end = 0;
            self.body_ends.extend(sizes.iter().map(|&n| {
                end += n;
                end
            }));
        }
    }

    /// The share of a force `force` on each of the particles `loaded` that the
    /// walls (`fix`) take, weighted by the force's components: per particle and
    /// component `Σ phi_i(x_p)` over the functions fixed in that component (the
    /// basis is a partition of unity, so 1 when every function a particle sees is
    /// fixed: the force goes into the wall and moves nothing). 0 for no particle
    /// or no force.
    pub fn share_held_by_walls(&self, loaded: &[usize], force: &[f64]) -> f64 {
        let weight: f64 = force.iter().take(D).map(|f| f.abs()).sum();
        if loaded.is_empty() || weight <= 0.0 {
            return 0.0;
        }
        let mut eval = BasisEval::for_basis(&self.basis);
        let mut held = 0.0;
        for &p in loaded {
            self.basis
                .eval(self.particles.element[p], &self.particles.x[p], &mut eval);
            for (fixed, f) in self.fixed.iter().zip(force) {
                let share: f64 = eval
                    .iter()
                    .filter(|&(i, _, _)| fixed[i])
                    .map(|(_, phi, _)| phi.to_f64())
                    .sum();
                held += f.abs() * share;
            }
        }
        held / (weight * loaded.len() as f64)
    }

    /// How the walls hold the initial motion of the particles `range`, per
    /// component `k`: the share of their momentum `Σ_p m_p |v_{p,k}|` that falls on
    /// the functions the walls hold in `k` (single-term constraints),
    /// `Σ_p m_p |v_{p,k}| Σ_{i held} phi_i(x_p)`, and the speed there against the
    /// mean speed: `(Σ_p m_p |v_{p,k}| Σ_{i held} phi_i / Σ_p m_p Σ_{i held} phi_i)`
    /// over `Σ_p m_p |v_{p,k}| / Σ_p m_p`; `(0, 0)` for a component without motion
    /// or held functions. The walls hold those functions both ways: the particles
    /// there take the walls' velocity, whichever way they move. A motion that
    /// vanishes at the walls (a bar vibrating between two) has its speed there well
    /// below the mean; a body moving as a whole, about the mean.
    pub fn motion_held_by_walls(&self, range: std::ops::Range<usize>) -> [(f64, f64); D] {
        let mut eval = BasisEval::for_basis(&self.basis);
        // Per component: Σ m |v| φ_held, Σ m φ_held, Σ m |v|, Σ m.
        let mut sums = [[0.0f64; 4]; D];
        for p in range {
            let m = self.particles.mass[p].to_f64();
            let v = &self.particles.v[p];
            self.basis
                .eval(self.particles.element[p], &self.particles.x[p], &mut eval);
            for (k, fixed) in self.fixed.iter().enumerate().take(D) {
                let speed = v[k].to_f64().abs();
                let held: f64 = eval
                    .iter()
                    .filter(|&(i, _, _)| fixed[i])
                    .map(|(_, phi, _)| phi.to_f64())
                    .sum();
                sums[k][0] += m * speed * held;
                sums[k][1] += m * held;
                sums[k][2] += m * speed;
                sums[k][3] += m;
            }
        }
        std::array::from_fn(|k| {
            let [near, held, momentum, mass] = sums[k];
            if momentum > 0.0 && held > 0.0 && mass > 0.0 {
                (near / momentum, (near / held) / (momentum / mass))
            } else {
                (0.0, 0.0)
            }
        })
    }

    /// Current time.
    pub fn time(&self) -> f64 {
        self.time
    }
    /// Steps taken.
    pub fn steps(&self) -> usize {
        self.step
    }
    /// The time step of [`Driver::step`] (which the watch over the critical step
    /// may take in sub-steps, [`Driver::watch_critical_step`]).
    pub fn dt(&self) -> f64 {
        self.dt_outer
    }
    /// Replaces the critical step of [`Driver::critical_time_step`] (by a bound
    /// the estimate exceeded, `setup::time_steps`): what the messages and the
    /// watch measure the step against.
    pub fn set_critical_step(&mut self, critical: f64) {
        self.dt_critical = Some(critical);
    }
    /// Changes the time step (e.g. to a fraction of [`Driver::critical_time_step`]).
    pub fn set_dt(&mut self, dt: f64) {
        self.dt_outer = dt;
        self.dt = T::of(dt);
        for effect in &mut self.effects {
            effect.set_time_step(dt);
        }
    }
    /// The step actually taken: `dt_outer` or a sub-step of it. The effects keep
    /// `dt_outer` ([`Effect::set_time_step`]): a contact wall's springs sized on it
    /// are softer than a sub-step needs, so they stay stable, and springs that
    /// stiffened and softened as steps are split would store and release energy.
    fn set_substep_dt(&mut self, dt: f64) {
        self.dt = T::of(dt);
    }
    /// What the watch over the critical step saw so far
    /// ([`Driver::watch_critical_step`]); `None` without the watch.
    pub fn watch_report(&self) -> Option<critical::WatchReport> {
        self.watch.as_ref().map(|w| critical::WatchReport {
            latest: w.latest,
            lowest: w.lowest,
            split_steps: w.split_steps,
            most_substeps: w.most_substeps,
            advected_steps: w.advected_steps,
            fastest: w.fastest,
        })
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

    /// Advances one time step: the phases in order, each timed. With the watch
    /// over the critical step ([`Driver::watch_critical_step`]) the step may be
    /// taken in equal sub-steps, each the whole sequence of phases; the report is
    /// that of the end of the step, its phase times the sub-steps' sum.
    pub fn step(&mut self) -> Result<StepReport, StepError> {
        let mut times = PhaseTimes::default();
        self.prepare_system(&mut times)?;
        let clock = Instant::now();
        let mut planned = self.substeps()?;
        times.solve += clock.elapsed().as_secs_f64();
        // The step's sub-steps: `planned` equal ones over the share of the step
        // from `begin`, of which `j` are taken; split again where the watch finds
        // the critical step fell within the step (`Driver::resplit_substeps`).
        let (mut begin, mut j, mut taken) = (0.0, 0, 0);
        self.set_substep_dt(self.dt_outer / planned as f64);
        loop {
            let end = (j + 1 < planned)
                .then(|| begin + (1.0 - begin) * ((j + 1) as f64 / planned as f64));
            let report = self.advance(end, &mut times)?;
            j += 1;
            taken += 1;
            if j == planned {
                self.book_substeps(taken);
                self.phases = times;
                return Ok(StepReport {
                    phases: times,
                    substeps: taken,
                    ..report
                });
            }
            let changes = self.element_changes;
            self.prepare_system(&mut times)?;
            let clock = Instant::now();
            let done = begin + (1.0 - begin) * (j as f64 / planned as f64);
            let remaining = self.dt_outer * (1.0 - done);
            let crossed = self.element_changes > changes;
            if let Some(k) = self.resplit_substeps(remaining, planned - j, crossed)? {
                (begin, j, planned) = (done, 0, k);
                self.set_substep_dt(remaining / k as f64);
            }
            times.solve += clock.elapsed().as_secs_f64();
        }
    }

    /// Phases 1, 2a and the factorisation: the particles located, the basis
    /// evaluated, `M` and `F^int` assembled and `M` factorised.
    fn prepare_system(&mut self, times: &mut PhaseTimes) -> Result<(), StepError> {
        let clock = Instant::now();
        self.locate_and_evaluate()?;
        let t_evaluate = clock.elapsed().as_secs_f64();
        self.assemble_mass();
        let t_assemble = clock.elapsed().as_secs_f64();
        self.factorize()?;
        times.evaluate += t_evaluate;
        times.assemble += t_assemble - t_evaluate;
        times.solve += clock.elapsed().as_secs_f64() - t_assemble;
        Ok(())
    }

    /// A sub-step from a factorised system ([`Driver::prepare_system`]): the
    /// effects' forces, both solves, the particles' update, and the report. `end`:
    /// the share of the step done after it, `None` for the step's last.
    fn advance(
        &mut self,
        end: Option<f64>,
        times: &mut PhaseTimes,
    ) -> Result<StepReport, StepError> {
        let clock = Instant::now();
        let previous = match self.previous_energy {
            Some(previous) => previous,
            None => {
                let e =
                    crate::diagnostics::energies(&self.particles, &self.material, &self.effects);
                (e.kinetic, e.strain + e.potential - self.work)
            }
        };
        self.assemble_effects();
        let t_assemble = clock.elapsed().as_secs_f64();
        let power_start = self.power_at_start()?;
        let (t_solve, t_projection, accelerate);
        if self.mass.solves_mass_itself() {
            // `M v̂ = P(vⁿ⁺¹) = P(vⁿ) + Δt M a`: with `M` itself solved,
            // `v̂ = M⁻¹ P(vⁿ) + Δt a`, both solves in one pass over the factor and
            // the particle velocities updated in phase 6.
            self.scatter_momentum();
            let before = clock.elapsed().as_secs_f64();
            self.solve_both()?;
            t_solve = clock.elapsed().as_secs_f64() - before;
            t_projection = 0.0;
            accelerate = true;
        } else {
            self.solve_acceleration()?;
            t_solve = clock.elapsed().as_secs_f64() - t_assemble;
            self.update_velocities_and_momentum()?;
            let before_projection = clock.elapsed().as_secs_f64();
            self.solve_projection()?;
            t_projection = clock.elapsed().as_secs_f64() - before_projection;
            accelerate = false;
        }
        self.book_work(power_start);
        self.update_particles(accelerate)?;
        times.assemble += t_assemble;
        times.solve += t_solve + t_projection;
        times.update += clock.elapsed().as_secs_f64() - t_assemble - t_solve - t_projection;
        // Time from the step count, so that it does not accumulate round-off.
        match end {
            Some(share) => self.time = (self.step as f64 + share) * self.dt_outer,
            None => {
                self.step += 1;
                self.time = self.step as f64 * self.dt_outer;
            }
        }
        let e = self.step_energies();
        let mut report = self.report_with(e);
        // ½ Σ m_p vⁿ·vⁿ⁺¹ = Kⁿ + ½ Σ m_p vⁿ·Δv_p, with the rest of the energy at xⁿ.
        // The work it pairs with: symplectic Euler changes it by exactly
        // `½ Δt v̂ᵏ⁺¹ · (Fᵏ + Fᵏ⁺¹)` per step on a linear system, the work booked up
        // to the last step (`Δt F · (v̂ᵏ + v̂ᵏ⁺¹) / 2`) plus half of this step's start
        // power `Fⁿ · v̂ⁿ`, less half of the first step's. With sub-steps `Δt` is the
        // sub-step's: `½ Δt Fⁿ · v̂ⁿ` is the part of `½ m vⁿ · vⁿ⁺¹` the step's
        // length puts in, which a change of the length changes with it.
        let dot: f64 = self.centred_terms.iter().sum();
        let half_power = 0.5 * self.dt.to_f64() * power_start[0];
        let first = *self.first_half_power.get_or_insert(half_power);
        report.total_centred = previous.0 + 0.5 * dot + previous.1 - (half_power - first);
        self.previous_energy = Some((report.kinetic, report.total_energy() - report.kinetic));
        Ok(report)
    }

    /// Locates the particles after the last step, so that a particle the last
    /// step carried out of the mesh fails the run as the next step would have
    /// (a run whose bodies fell out of the mesh in its last step was reported
    /// complete). The error names the last step, the one that moved it.
    pub fn check_in_mesh(&mut self) -> Result<(), StepError> {
        self.locate_at(self.step)
    }

    /// Phase 1.
    fn locate_and_evaluate(&mut self) -> Result<(), StepError> {
        self.locate_at(self.step + 1)
    }

    /// Phase 1, a failure reported at `step`.
    fn locate_at(&mut self, step: usize) -> Result<(), StepError> {
        phases::locate_and_evaluate(
            &self.basis,
            &self.particles.x,
            &mut self.particles.element,
            &mut self.bins,
            &mut self.scratch,
            &mut self.evals,
        )
        .map(|crossed| {
            self.element_changes += crossed as u64;
            self.gather.mark_live(&self.basis, &self.bins);
            self.inputs
                .mark_touching(&self.basis, &self.particles, &self.bins, &self.gather);
        })
        .map_err(|o| {
            let p = o.particle;
            let speed = self.particles.v[p].norm().to_f64();
            let moved = speed * self.dt.to_f64();
            // The element it was in before this step (location failed, so the
            // particle's element is still the last one found).
            let from = self.particles.element[p];
            // The contact distance a particle placed closer to a contact wall keeps.
            let started = self.effects.iter().find_map(|e| e.contact_distance(p));
            let nominal =
                crate::contact::contact_distance::<D>(self.particles.volume0[p].to_f64());
            let hint = if let Some(room) = started.filter(|&d| d < STARTED_CLOSE * nominal) {
                format!(
                    "it moved {moved:.3e} in the last step at speed {speed:.3e} and went through a contact wall it started {} from, where the wall starts to push at half a particle spacing ({}): the body was placed overlapping the wall's contact layer, so its springs there had {} of room, and a step's small motion took it through; move the body off the wall so that its particles start at least {} from it (a `box` body whose side lies on an axis wall has them there; a lattice not aligned with a slanted wall puts some closer: move such a body off by half a spacing); a smaller step lets the springs hold with less room, but leaves the room as small",
                    crate::scene::limits::echo_significant(room.max(0.0), 3),
                    crate::scene::limits::echo_significant(nominal, 3),
                    crate::scene::limits::echo_significant(room.max(0.0), 3),
                    crate::scene::limits::echo_significant(nominal, 3),
                )
            } else if self.effects.iter().any(|e| {
                let x = to_f64(&self.particles.x[p]);
                e.went_through(from, [x[0], if D > 1 { x[1] } else { 0.0 }])
            }) {
                let distance = nominal;
                let how = if moved < 0.25 * distance {
                    format!(
                        "a small part of its contact distance ({}): it was pressed through over several steps, the springs too soft for the load (a landing body whose weight and momentum bear on one or a few particles, as a disk's lowest particle at its first landing, needs a step at which those few springs carry it)",
                        crate::scene::limits::echo_significant(distance, 3)
                    )
                } else {
                    format!(
                        "more than a quarter of its contact distance ({}): too fast for the springs",
                        crate::scene::limits::echo_significant(distance, 3)
                    )
                };
                // Half the step; for an impact (a fast particle) at most 0.25, which
                // impacts on contact walls want: a disk dropped onto a contact floor
                // at 0.8 went through again at the half, 0.4, and held at 0.25.
                // The step the scene's `courant` sets, before any split.
                let courant = self.dt_critical.map_or(String::new(), |critical| {
                    let now = self.dt_outer / critical;
                    let impact = moved >= 0.25 * distance;
                    let to = if impact { (0.5 * now).min(0.25) } else { 0.5 * now };
                    format!(
                        " from {} to {}",
                        crate::scene::limits::echo_significant(now, 2),
                        crate::scene::limits::echo_significant(to, 2)
                    )
                });
                // Steps split for the particles' speeds keep their sub-steps as the
                // step shrinks, until `courant` falls below the sub-steps' own.
                if let (Some((critical, speeds)), Some(c)) =
                    (self.watch.as_ref().map(|w| w.pending), self.dt_critical)
                {
                    if speeds > critical.max(1) {
                        let sub = self.dt.to_f64() / c;
                        return StepError::ParticleLeftMesh {
                            step,
                            particle: p,
                            position: to_f64(&self.particles.x[p]),
                            hint: format!(
                                "it moved {moved:.3e} in the last sub-step at speed {speed:.3e}, {how}, and went through a contact wall, although the step was split {speeds} ways for the particles' speeds, each sub-step at a Courant number of {}: the wall's springs are sized on the step, not its sub-steps (`m (κ/Δt)²`, so that splitting a step does not stiffen and soften them, which stores and releases energy); lower `time.courant` from {} to {} (half the step makes them four times stiffer) or raise the wall's `stiffness` a little (0.5 by default; at 1 the contact itself can grow unstable); an impact much faster than the body's wave speed √(E/ρ) crushes the body whatever the step; if the speed is unphysical, the run became unstable earlier (see the energy column)",
                                crate::scene::limits::echo_significant(sub, 2),
                                crate::scene::limits::echo_significant(self.dt_outer / c, 2),
                                // Half the number shown (0.14 → 0.07, not 0.069).
                                crate::scene::limits::echo_significant(
                                    0.5 * crate::scene::limits::significant(self.dt_outer / c, 2),
                                    2
                                )
                            ),
                        };
                    }
                }
                format!(
                    "it moved {moved:.3e} in the last step at speed {speed:.3e}, {how}, and went through a contact wall: lower `time.courant`{courant} (a wall's springs are `m (κ/Δt)²` stiff, so half the step makes them four times stiffer; impacts on contact walls want 0.25 or less, soft or heavy bodies pressed on few particles less) or, where a wall's `stiffness` is below its default 0.5, raise it (below about 0.25 the springs let an impact through: an L body striking a wedge at 5.9 m/s went through at 0.02 and 0.1 and held at 0.25 and 0.5; at 1 the contact itself can grow unstable); if the speed is unphysical, the run became unstable earlier (see the energy column)"
                )
            } else if let Some((_, vertex)) = self.slip_bends.iter().find(|(functions, _)| {
                self.basis
                    .element_functions(from)
                    .iter()
                    .any(|i| functions.contains(i))
            }) {
                format!(
                    "it moved {moved:.3e} in the last step at speed {speed:.3e} and went out at the bend where two slip walls meet at {}: there the walls hold the velocity along their mean normal (else the vertex would hold still and stop a body sliding over it), which lets a body sliding into a valley cross each wall near the vertex by sin(θ/2) of its speed, θ the bend; for a floor a body slides over, make its walls contact walls (an `[[effect]]` with `kind = \"contact-wall\"` per `tag`, in place of the `[[boundary]]`s), which hold a body from outside without holding the vertex",
                    point(vertex)
                )
            } else if self
                .basis
                .element_functions(from)
                .iter()
                .any(|&i| self.walled[i])
            {
                format!(
                    "it moved {moved:.3e} in the last step at speed {speed:.3e} and went out of an element that a wall (`fix`) holds functions of: if it crossed the wall, a wall holds the velocity of the functions on it, not of each particle, and a particle that moves a large part of an element in one step can cross it: lower `time.courant` (or `time.dt`); if it left through a free side beside the wall, add a wall there or enlarge the mesh; if the speed is unphysical, the run became unstable earlier (see the energy column)"
                )
            } else if moved > self.element_width[from] {
                // Across elements in one step: a `fix` wall holds the grid's
                // velocity at the boundary, and a particle carried past it in one
                // step leaves the mesh whatever the walls.
                let watch = if self.watch.is_none() {
                    "the watch over the step is off (`--no-watch`), which splits a step that would carry a particle more than half its element: turn it on, or "
                } else {
                    ""
                };
                format!(
                    "it moved {moved:.3e} in the last step at speed {speed:.3e}, {:.0} widths of its element: a step that carries a particle across elements takes it through the mesh's walls (a `fix` wall holds the grid's velocity at the boundary, not a particle carried past it); {watch}lower the step (`time.courant` or `dt`); if the speed is unphysical, the run became unstable earlier (see the energy column)",
                    moved / self.element_width[from]
                )
            } else {
                format!(
                    "it moved {moved:.3e} in the last step at speed {speed:.3e}: if the body should stay inside, add a wall (`fix`, or a contact wall) on that side of the mesh or enlarge the mesh; if the speed is unphysical, the run became unstable earlier (see the energy column)"
                )
            };
            // A spinning body of the paper's non-objective law is crushed or torn by
            // its spurious stress: that first, whichever way it failed.
            let hint = match crate::material::non_objective_cause(self.non_objective_rotation(p)) {
                Some(law) => format!("{hint}; before anything else: {law}"),
                None => hint,
            };
            StepError::ParticleLeftMesh {
                step,
                particle: p,
                position: to_f64(&self.particles.x[p]),
                hint,
            }
        })
    }

    /// Phase 2a: `M`, `F = −F^int` into `rhs`, and the facts the mass strategy
    /// asked for.
    fn assemble_mass(&mut self) {
        let body = !self.body_force.is_empty() && self.fill_particle_forces(false);
        phases::assemble_mass_and_internal_force(
            &self.particles,
            &self.evals,
            &self.bins,
            &mut self.gather,
            &mut self.local,
            if self.inputs.needs.row_sums_only {
                phases::MassMatrix::RowSums
            } else {
                phases::MassMatrix::Full
            },
            &mut self.values,
            &mut self.rhs,
            self.inputs.needs.coverage.then_some((
                &mut self.inputs.particle_volume[..],
                &mut self.inputs.particle_count[..],
            )),
            body.then_some((&self.particle_force[..], &mut self.body_force[..])),
        );
        if self.inputs.needs.empty_elements {
            phases::mark_empty_elements(
                &self.basis,
                &self.bins,
                self.inputs
                    .touching
                    .as_ref()
                    .unwrap_or(&phases::Touching::default()),
                &mut self.inputs.touches_empty,
            );
        }
        if self.inputs.needs.correction == Correction::InMass {
            if !self.inputs.flat.is_empty() {
                phases::mark_flat_functions(
                    &self.basis,
                    &self.bins,
                    &self.particles.mass,
                    &self.particles.x,
                    &self.element_scale,
                    &self.gather,
                    &mut self.inputs.flat,
                );
            }
            let context = StepContext {
                touches_empty: &self.inputs.touches_empty,
                particle_volume: &self.inputs.particle_volume,
                particle_count: &self.inputs.particle_count,
                on_wall: &self.inputs.on_wall,
                live: if self.inputs.touching.is_some() {
                    &self.inputs.live
                } else {
                    self.gather.live()
                },
                live_list: if self.inputs.touching.is_some() {
                    self.inputs.live_list()
                } else {
                    self.gather.live_list()
                },
                diagonal_only: self.inputs.needs.row_sums_only,
                flat: &self.inputs.flat,
            };
            if let Some(lumped) = self.mass.classify(&self.pattern, &self.values, context) {
                self.inputs.fill_touching(&self.basis, &self.particles);
                phases::add_affine_lumping(
                    &self.evals,
                    &self.bins,
                    self.inputs.touching.as_ref().unwrap(),
                    &mut self.inputs.element_affine,
                    &mut self.inputs.function_pinned,
                    &self.gather,
                    &mut self.local,
                    &self.particles.mass,
                    &self.particles.x,
                    &self.function_points,
                    &self.element_scale,
                    self.functions_affine,
                    lumped,
                    &mut self.values,
                );
            }
        }
    }

    /// Phase 2b, after [`assemble_mass`](Self::assemble_mass): the effects' forces
    /// into `rhs`.
    fn assemble_effects(&mut self) {
        if self.effects.is_empty() {
            return;
        }
        let state = StepState {
            time: self.time,
            dt: self.dt.to_f64(),
            basis: ParticleBasis { evals: &self.evals },
        };
        let tracks_work = !self.work_force.is_empty();
        if tracks_work {
            phases::zero(&mut self.work_force);
        }
        if !self.dissipative_force.is_empty() {
            phases::zero(&mut self.dissipative_force);
        }
        for effect in self.effects.iter().filter(|e| !e.acts_per_particle()) {
            if effect.does_work() {
                effect.add_forces(&self.particles, &state, &mut self.work_force);
                if effect.dissipative() {
                    effect.add_forces(&self.particles, &state, &mut self.dissipative_force);
                }
            } else {
                effect.add_forces(&self.particles, &state, &mut self.rhs);
            }
        }
        if !self.body_force.is_empty() {
            self.gather.add_live(&self.body_force, &mut self.rhs);
        }
        self.scatter_working_particle_forces();
        if tracks_work {
            phases::add_into(&mut self.rhs, &self.work_force);
        }
        // Corrections from the total force (damping, eq. (49)), all from the same total.
        phases::zero(&mut self.adjust);
        for effect in &self.effects {
            if effect.does_work() {
                effect.adjust_forces(&self.rhs, &self.velocity, &mut self.work_force);
                if effect.dissipative() {
                    effect.adjust_forces(&self.rhs, &self.velocity, &mut self.dissipative_force);
                }
            }
            effect.adjust_forces(&self.rhs, &self.velocity, &mut self.adjust);
        }
        phases::add_into(&mut self.rhs, &self.adjust);
    }

    /// The forces of the effects that act per particle and do work (`work`) or
    /// not, summed per particle in the effects' order into `particle_force`;
    /// `false` (and nothing written) without such an effect.
    fn fill_particle_forces(&mut self, work: bool) -> bool {
        let acting = move |e: &dyn Effect<T, D>| e.acts_per_particle() && e.does_work() == work;
        if !self.effects.iter().any(|e| acting(e.as_ref())) {
            return false;
        }
        let (effects, particles, time) = (&self.effects, &self.particles, self.time);
        self.particle_force
            .par_chunks_mut(phases::CHUNK)
            .enumerate()
            .for_each(|(c, forces)| {
                for (q, f) in forces.iter_mut().enumerate() {
                    let p = c * phases::CHUNK + q;
                    *f = SVector::zeros();
                    for effect in effects.iter().filter(|e| acting(e.as_ref())) {
                        if let Some(force) = effect.particle_force(particles, p, time) {
                            *f += force;
                        }
                    }
                }
            });
        true
    }

    /// The forces of the effects that act per particle and do work, scattered
    /// into `work_force` (those that do not are summed in phase 2a's pass,
    /// `body_force`, and added to `rhs` by [`assemble_effects`](Self::assemble_effects)).
    fn scatter_working_particle_forces(&mut self) {
        if !self.fill_particle_forces(true) {
            return;
        }
        let (evals, forces) = (&self.evals, &self.particle_force);
        phases::scatter_by_elements(
            &self.bins,
            evals,
            &self.gather,
            &mut self.local,
            &mut self.work_force,
            |p, s| forces[p] * evals.phi[s],
        );
    }

    /// Phase 3a: the strategy's numeric work on `M`, the condition estimate when
    /// requested, and the constraint projection for the step.
    fn factorize(&mut self) -> Result<(), StepError> {
        let context = StepContext {
            touches_empty: &self.inputs.touches_empty,
            particle_volume: &self.inputs.particle_volume,
            particle_count: &self.inputs.particle_count,
            on_wall: &self.inputs.on_wall,
            live: self.gather.live(),
            live_list: self.gather.live_list(),
            diagonal_only: self.inputs.needs.row_sums_only,
            flat: &self.inputs.flat,
        };
        match self.mass.factorize(&self.pattern, &self.values, context) {
            Ok(report) => self.last_report = report,
            Err(source) => return Err(self.mass_failure(source)),
        }
        self.last_condition = self
            .estimate_condition
            .then(|| self.mass.condition_estimate(&self.pattern));
        self.constraints
            .prepare(&mut self.mass, |i| {
                self.values[self.pattern.diagonal_position(i)] > T::zero()
            })
            .map_err(|source| self.mass_failure(source))
    }

    /// Solves component by component and projects onto the general constraints.
    fn solve_projected(&mut self, which: Which) -> Result<(), StepError> {
        let target = match which {
            Which::Acceleration => &mut self.rhs,
            Which::Velocity => &mut self.velocity,
        };
        solve_with_walls(&mut self.mass, &mut self.constraints, target)
            .map_err(|source| self.mass_failure(source))
    }

    /// Phase 3b: `M a = F` (eq. (17)).
    fn solve_acceleration(&mut self) -> Result<(), StepError> {
        self.solve_projected(Which::Acceleration)
    }

    /// Phase 5: `M v̂ = P` (eq. (20)).
    fn solve_projection(&mut self) -> Result<(), StepError> {
        self.solve_projected(Which::Velocity)
    }

    /// `P(vⁿ)_i = Σ_p m_p phi_i(x_p) vⁿ_p` into `velocity`.
    pub(super) fn scatter_momentum(&mut self) {
        phases::zero(&mut self.velocity);
        phases::scatter_to_functions(
            &self.evals,
            &self.bins,
            &self.gather,
            &mut self.local,
            &self.particles.mass,
            &self.particles.v,
            &mut self.velocity,
        );
    }

    /// Phases 3b and 5 at once for a strategy that solves `M` itself: `a = M⁻¹ F`
    /// (eq. (17)) and `v̂ = M⁻¹ P(vⁿ) + Δt a`, which is `M⁻¹ P(vⁿ⁺¹)` (eq. (20))
    /// since `P(vⁿ⁺¹) = P(vⁿ) + Δt M a` (eq. (18)); both projected onto the general
    /// constraints (a linear projection that leaves `a` as it is).
    fn solve_both(&mut self) -> Result<(), StepError> {
        if let Err(source) = self.mass.solve_all_two(&mut self.rhs, &mut self.velocity) {
            return Err(self.mass_failure(source));
        }
        self.last_report.held_force_share = self.mass.held_force_share();
        self.constraints.project(&mut self.rhs);
        self.constraints.project(&mut self.velocity);
        let dt = self.dt;
        for (v, a) in self.velocity.iter_mut().zip(&self.rhs) {
            for (v, &a) in v.iter_mut().zip(a) {
                *v += dt * a;
            }
        }
        Ok(())
    }

    /// Phases 4–5: particle velocities and momentum, with the affine correction
    /// when the strategy lumped rows and asked for it (it needs `v̂ⁿ`, projected
    /// from the initial velocities before the first step).
    fn update_velocities_and_momentum(&mut self) -> Result<(), StepError> {
        // `Some` only for a strategy that asked for a correction (`Needs::correction`)
        // and lumped rows in this step.
        if self.mass.lumped_rows().is_some() && !self.velocity_known {
            self.project_initial_velocity()?;
        }
        let rigid = self.inputs.needs.correction == Correction::Rigid;
        let affine = self.mass.lumped_rows().map(|decoupled| phases::Affine {
            decoupled,
            points: &self.function_points,
            gradient: &mut self.affine_gradient,
            rigid,
        });
        phases::update_velocities_and_momentum(
            &self.evals,
            &self.bins,
            &self.gather,
            &mut self.local,
            &self.rhs,
            self.dt,
            &self.particles.mass,
            &mut self.particles.v,
            &mut self.velocity,
            affine,
            &mut self.centred_terms,
        );
        Ok(())
    }

    /// Phase 6: deformation, stress, volume and positions (eqs. (22)–(31)).
    fn update_particles(&mut self, accelerate: bool) -> Result<(), StepError> {
        phases::update_particles(
            &self.evals,
            &self.velocity,
            accelerate.then_some(self.rhs.as_slice()),
            self.dt,
            &self.material,
            &mut self.particles,
            (&mut self.energy_terms, &mut self.centred_terms),
        )
        .map_err(|failure| {
            let (particle, quantity) = match failure {
                UpdateFailure::Jacobian { particle, .. } => {
                    (particle, "the Jacobian det F (non-positive or NaN)")
                }
                UpdateFailure::NotFinite { particle } => (particle, "position or velocity"),
            };
            StepError::NotFinite {
                step: self.step + 1,
                quantity,
                particle,
                position: to_f64(&self.particles.x[particle]),
                hint: self.diagnose_particle(particle),
            }
        })
    }
}

/// `f ← M⁻¹ f` for every component with the strategy's solve, then projected onto
/// the general constraints: the solve of phases 3b and 5, and of the critical-step
/// estimates ([`critical`]).
fn solve_with_walls<T: Scalar, const D: usize, M: MassStrategy<T>>(
    mass: &mut M,
    constraints: &mut Constraints<T, D>,
    f: &mut [Vec<T>],
) -> Result<(), crate::mass::MassError> {
    mass.solve_all(f)?;
    constraints.project(f);
    Ok(())
}

#[derive(Clone, Copy)]
enum Which {
    Acceleration,
    Velocity,
}

/// `on_wall[i]`: some component of function `i` is fixed, or a general
/// constraint has a term on it.
fn on_wall<T>(n: usize, fixed: &[Vec<bool>], general: &[Vec<(usize, usize, T)>]) -> Vec<bool> {
    let mut on_wall = vec![false; n];
    for component in fixed {
        for (wall, &f) in on_wall.iter_mut().zip(component) {
            *wall |= f;
        }
    }
    mark_terms(&mut on_wall, general);
    on_wall
}

/// Marks every function a term of the general constraints `rows` acts on.
/// Two slip walls meeting at a bend ([`Driver::average_slip_bends`]): their tags,
/// their unit (outward) normals, and the vertex they share.
#[derive(Debug, Clone)]
pub struct SlipBend<T: Scalar, const D: usize> {
    pub tags: [String; 2],
    pub normals: [SVector<T, D>; 2],
    pub vertex: SVector<T, D>,
}

/// The row a wall of unit normal `normal` holds for the combination `terms` of
/// coefficients: `Σ w c_i · normal`, as `(component, function, weight)`.
fn expand_row<T: Scalar, const D: usize>(
    terms: &[(usize, T)],
    normal: &SVector<T, D>,
) -> Vec<(usize, usize, T)> {
    let mut row = Vec::new();
    for &(i, w) in terms {
        for k in 0..D {
            if normal[k] != T::zero() {
                row.push((k, i, w * normal[k]));
            }
        }
    }
    row
}

/// The axis a unit normal lies along, if any.
fn single_axis<T: Scalar, const D: usize>(normal: &SVector<T, D>) -> Option<usize> {
    let along: Vec<usize> = (0..D).filter(|&k| normal[k] != T::zero()).collect();
    (along.len() == 1).then(|| along[0])
}

fn mark_terms<T>(on_wall: &mut [bool], rows: &[Vec<(usize, usize, T)>]) {
    for &(_, i, _) in rows.iter().flatten() {
        on_wall[i] = true;
    }
}

fn to_f64<T: Scalar, const D: usize>(x: &SVector<T, D>) -> Vec<f64> {
    x.iter().map(|v| v.to_f64()).collect()
}

fn to_f64_point<const D: usize>(x: &SVector<f64, D>) -> Vec<f64> {
    x.iter().copied().collect()
}

#[cfg(test)]
mod tests;
