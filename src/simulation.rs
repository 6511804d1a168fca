//! Running a [`Scene`]: set it up ([`crate::setup`]: mesh, basis, particles, effects,
//! driver), step to the end time, and measure the error against the scene's reference
//! solution.
//!
//! The run reports every step through a callback (the CLI prints from it, tests read
//! the same values) and ends with a [`Summary`]. A run that fails numerically (a
//! particle leaves the mesh, the mass matrix is not positive definite, a value is not
//! finite) is not an `Err`: its summary says `stable = false` with the reason and the
//! step, and everything measured up to there, so that instabilities are reported as
//! results. `Err` is for scenes that cannot be set up.
//!
//! "Stable" follows the benchmark definitions of the seeds (paper and thesis, as checked against their tables): no failure, the total energy
//! (kinetic + strain + gravitational − work of the non-conservative effects), taken
//! time-centred (`½ Σ m vⁿ·vⁿ⁺¹` for the kinetic energy, which the step's swing after
//! an impact does not move; since 2026-12-04), never
//! exceeds its initial value by more than [`STABLE_ENERGY_GROWTH`] of the energy
//! scale (the largest kinetic plus strain energy, or the range swept by the potential
//! energy or the work of the effects, so that moving a scene or writing gravity as a
//! body force does not change the verdict: [`crate::diagnostics::Verdict`]), and
//! every condition estimate (when requested) stays below [`STABLE_CONDITION`].

pub use crate::arrangement::{
    fragments, pieces, pieces_warning, stray_particles, stray_warning, Fragments, STRAY_DISTANCE,
    STRAY_WARNING,
};
use crate::body_contact::PerBody;
use crate::diagnostics::Verdict;
use crate::driver::{BodySampling, PhaseTimes, StepError, StepReport};
use crate::particles::Particles;
use crate::scene::limits::{echo_fixed, echo_number};
use crate::scene::{Scene, SceneError};
use crate::setup::{self, from_vec, Basis1d, Basis2d, Domain, Prepared, Solution};
use crate::studies::exact;
use psmpm_basis::Basis;
use serde::Serialize;
use std::sync::atomic::{AtomicBool, Ordering};

pub use crate::setup::{build_effects, particle_lattice, triangulation, Lattice};

pub use crate::diagnostics::{STABLE_CONDITION, STABLE_ENERGY_GROWTH};

/// Steps between two samples of [`Summary::max_rotation`].
pub const ROTATION_EVERY: usize = 10;

/// Why a scene could not be run: typed, so that a caller can locate the field in
/// the scene file without reading it back out of the message.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// A scene value the set-up cannot use: its field, the kind of problem and
    /// what is wrong.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The reference solution of a study could not be computed.
    #[error("{0}")]
    Reference(String),
    /// A name that is neither a built-in scene nor a study (the message lists the
    /// known ones).
    #[error("{0}")]
    UnknownName(String),
}

/// A tracked particle (`output.tracked`) at the end of a run, for the JSON summary.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackedEnd {
    /// Where it started.
    pub started_at: Vec<f64>,
    /// Its displacement at the end of the run (or where the run stopped).
    pub displacement: Vec<f64>,
}

/// What a run produced.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: String,
    /// Basis name.
    pub basis: &'static str,
    /// Mass strategy.
    pub mass: String,
    /// Basis functions.
    pub functions: usize,
    /// Particles.
    pub particles: usize,
    /// Steps taken.
    pub steps: usize,
    /// Time step.
    pub dt: f64,
    /// End time reached.
    pub t_end: f64,
    /// Error against the reference solution (see `error_measure`), `None` without one.
    pub error: Option<f64>,
    /// What `error` measures: `E_u` (thesis eq. (4.4)), `rms-position` (paper
    /// eq. (47)), `max-relative-sigma-yy` (paper eq. (48); `max-relative-sigma-xx`
    /// in 1D, whose one stress is σ_xx).
    pub error_measure: Option<&'static str>,
    /// Largest number of lumped rows in a step.
    pub max_lumped_rows: usize,
    /// Largest number of deactivated functions in a step.
    pub max_deactivated: usize,
    /// Most functions the extension expressed through their neighbours in a step.
    pub max_extended: usize,
    /// The critical time step of the basis, mass strategy and material at the start
    /// ([`crate::driver::Driver::critical_time_step`]), when it could be estimated.
    pub dt_critical: Option<f64>,
    /// The scene's Courant number `C` when it sets the step (`Δt = C Δt_crit`,
    /// shortened to end at `t_end`; `dt / dt_critical` is the ratio the run used),
    /// `None` when the scene gives `dt`.
    pub courant: Option<f64>,
    /// The lowest critical step estimated while the bodies moved (the watch over
    /// the critical step, [`crate::driver::Driver::watch_critical_step`]), when
    /// watched; `dt_critical` is the start's.
    pub dt_critical_lowest: Option<f64>,
    /// Steps the watch took in sub-steps, the critical step having fallen below
    /// what the step needs (`setup::watch_thresholds`).
    pub split_steps: usize,
    /// The most sub-steps of one step (1 when none was split).
    pub most_substeps: usize,
    /// Steps the watch split further than the critical step needs, to keep every
    /// particle's move within its element (or a contact wall's reach):
    /// `crate::driver::critical::ADVECTION_SHARE`.
    pub advected_steps: usize,
    /// The largest particle speed that split a step so, when one did.
    pub fastest_speed: Option<f64>,
    /// Largest condition-number estimate (when requested).
    pub max_condition: Option<f64>,
    /// Total energy at the start.
    pub energy_initial: f64,
    /// Total energy at the end.
    pub energy_final: f64,
    /// The energy scale the drift and growth are relative to
    /// ([`crate::diagnostics::Verdict::scale`]).
    pub energy_scale: f64,
    /// Largest `|E(t) − E(0)|` relative to the energy scale of the run (the largest
    /// kinetic plus strain energy, or the range swept by the potential energy or by
    /// the work of the effects: [`crate::diagnostics::Verdict`]).
    pub energy_drift: f64,
    /// Largest `E(t) − E(0)` relative to the energy scale (growth only).
    pub energy_growth: f64,
    /// The same for the time-centred total
    /// ([`crate::diagnostics::StepReport::total_centred`]): the growth that is not
    /// the explicit step's oscillation.
    pub energy_growth_centred: f64,
    /// The verdict of the module doc.
    pub stable: bool,
    /// When the verdict broke the energy bound without a failed step: when the
    /// growth crossed it, the time step against the critical one, the particles per
    /// element, and the fix that fits ([`energy_growth_hint`]). Not in the JSON
    /// summary.
    #[serde(skip)]
    pub energy_growth_hint: Option<String>,
    /// Why the run stopped early, with the step: a failed step, or a body
    /// collapsed (a particle's `det F` below [`crate::material::COLLAPSED_JACOBIAN`],
    /// checked every [`ROTATION_EVERY`] steps and at the end).
    pub failure: Option<String>,
    /// Largest rotation angle (radians) of the polar factor `R` of any particle's
    /// `F = R U`, sampled every [`ROTATION_EVERY`] steps and at the end (0 in 1D).
    /// Not in the JSON summary (the warning carries it when it matters).
    #[serde(skip)]
    pub max_rotation: f64,
    /// How far the particles left the arrangement they started in at the end
    /// ([`crate::arrangement::irregularity`]). Not in the JSON summary (the warning
    /// carries it when it matters).
    #[serde(skip)]
    pub irregularity: crate::arrangement::Irregularity,
    /// Warnings about the run, each once: the paper's non-objective law
    /// (`linear-elastic`) under a rotation above [`crate::material::ROTATION_WARNING`].
    /// Always in the JSON summary (`[]` without any), so that a script can read it.
    pub warnings: Vec<String>,
    /// The run was stopped from outside (the stop flag of [`observe_2d_until`])
    /// before its end time; the rest of the summary covers the steps taken. Not
    /// serialised when false.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub interrupted: bool,
    /// Deactivation held functions with particles at zero velocity that the
    /// bodies' motion needed (its warning, [`deactivation_warning`]): stable in
    /// energy, but the bodies hang from or rest on them as on a wall, which the
    /// verdict does not see. Not serialised when false.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub held_by_deactivation: bool,
    /// Each tracked particle's (`output.tracked`) starting position and its
    /// displacement at the end of the run, in the scene's order (`mpm-cli
    /// compare` prints the first). Not in the JSON summary (`tracked.csv` holds
    /// the histories).
    #[serde(skip)]
    pub tracked_end: Vec<([f64; 2], [f64; 2])>,
    /// The same for the JSON summary (`tracked_end`, `--format json` of `run` and
    /// `compare`), in the scene's dimension; left out without tracked points.
    #[serde(rename = "tracked_end", skip_serializing_if = "Vec::is_empty")]
    pub tracked_end_json: Vec<TrackedEnd>,
    /// Connected pieces the particles form at the start and at the end
    /// ([`pieces`]; every body counted on its own): more at the end than at the
    /// start means a body came apart, which the energy verdict does not judge.
    pub pieces: [usize; 2],
    /// Stray particles (no other within [`STRAY_DISTANCE`] of their spacing) at
    /// the start and at the end ([`stray_particles`]).
    pub stray: [usize; 2],
    /// Wall time of the time loop.
    pub seconds: f64,
    /// Wall time per phase, summed over the steps.
    #[serde(skip)]
    pub phases: PhaseTimes,
}

impl Summary {
    /// The particles form more pieces at the end than at the start, or enough of
    /// them became stray ([`crate::arrangement::strayed`]): a body came apart (the warnings say how), which the energy verdict does not
    /// judge.
    pub fn came_apart(&self) -> bool {
        self.pieces[1] > self.pieces[0]
            || crate::arrangement::strayed(self.stray[0], self.stray[1], self.particles)
    }
}

/// The history of one tracked particle.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Tracked {
    /// Particle index.
    pub particle: usize,
    /// Initial position.
    pub x0: [f64; 2],
    /// Times after each step.
    pub time: Vec<f64>,
    /// Velocity after each step.
    pub velocity: Vec<[f64; 2]>,
    /// Displacement after each step.
    pub displacement: Vec<[f64; 2]>,
    /// The reference displacement at the same times (when the scene has one).
    pub exact_displacement: Vec<[f64; 2]>,
    /// The reference velocity at the same times (when the scene has one).
    pub exact_velocity: Vec<[f64; 2]>,
}

/// A run's particles and histories at the end, for tests and output.
pub struct Outcome<const D: usize> {
    /// Summary.
    pub summary: Summary,
    /// Particles at the end.
    pub particles: Particles<f64, D>,
    /// Tracked particles.
    pub tracked: Vec<Tracked>,
    /// The numerical failure that ended the run early.
    pub failure: Option<StepError>,
}

/// The particles of a run, in its dimension, as observers see them after a step.
#[derive(Clone, Copy)]
pub enum ParticlesRef<'a> {
    /// A 1D run.
    One(&'a Particles<f64, 1>),
    /// A 2D run.
    Two(&'a Particles<f64, 2>),
}

/// Particle sets that can be shown to observers.
pub trait AsParticlesRef {
    /// The view.
    fn view(&self) -> ParticlesRef<'_>;
}

impl AsParticlesRef for Particles<f64, 1> {
    fn view(&self) -> ParticlesRef<'_> {
        ParticlesRef::One(self)
    }
}

impl AsParticlesRef for Particles<f64, 2> {
    fn view(&self) -> ParticlesRef<'_> {
        ParticlesRef::Two(self)
    }
}

/// A callback after every step, with the step's report and the particles.
pub type Observer<'a> = dyn FnMut(&StepReport, ParticlesRef<'_>) + 'a;

/// Runs `scene` (1D or 2D), calling `on_step` after every step.
pub fn run(scene: &Scene, on_step: &mut dyn FnMut(&StepReport)) -> Result<Summary, RunError> {
    observe(scene, &mut |r, _| on_step(r))
}

/// [`run`] that stops after the step during which `stop` became true (checked
/// between steps); the summary then says `interrupted`.
pub fn run_until(
    scene: &Scene,
    on_step: &mut dyn FnMut(&StepReport),
    stop: &AtomicBool,
) -> Result<Summary, RunError> {
    let mut steps_only = |r: &StepReport, _: ParticlesRef<'_>| {
        if r.step > 0 {
            on_step(r)
        }
    };
    match scene.dim {
        2 => run_2d_observed(scene, &mut steps_only, Some(stop)).map(|o| o.summary),
        _ => run_1d_observed(scene, &mut steps_only, Some(stop)).map(|o| o.summary),
    }
}

/// Runs `scene` (1D or 2D), showing every step's report and particles to `observer`.
pub fn observe(scene: &Scene, observer: &mut Observer) -> Result<Summary, RunError> {
    let mut steps_only = |r: &StepReport, p: ParticlesRef<'_>| {
        if r.step > 0 {
            observer(r, p)
        }
    };
    match scene.dim {
        2 => run_2d_observed(scene, &mut steps_only, None).map(|o| o.summary),
        _ => run_1d_observed(scene, &mut steps_only, None).map(|o| o.summary),
    }
}

/// Runs a 2D scene, showing `observer` the initial state (a report with `step == 0`)
/// and then every step, and returns its particles and tracked histories.
pub fn observe_2d(scene: &Scene, observer: &mut Observer) -> Result<Outcome<2>, RunError> {
    run_2d_observed(scene, observer, None)
}

/// [`observe_2d`] that stops after the step during which `stop` became true (checked
/// between steps); the summary then says `interrupted`.
pub fn observe_2d_until(
    scene: &Scene,
    observer: &mut Observer,
    stop: &AtomicBool,
) -> Result<Outcome<2>, RunError> {
    run_2d_observed(scene, observer, Some(stop))
}

/// [`observe_1d`] that stops early as [`observe_2d_until`] does.
pub fn observe_1d_until(
    scene: &Scene,
    observer: &mut Observer,
    stop: &AtomicBool,
) -> Result<Outcome<1>, RunError> {
    run_1d_observed(scene, observer, Some(stop))
}

/// Runs a 1D scene, showing `observer` the initial state (a report with `step == 0`)
/// and then every step, and returns its particles and tracked histories.
pub fn observe_1d(scene: &Scene, observer: &mut Observer) -> Result<Outcome<1>, RunError> {
    run_1d_observed(scene, observer, None)
}

/// Runs a 2D scene and returns its particles too.
pub fn run_2d(scene: &Scene, on_step: &mut dyn FnMut(&StepReport)) -> Result<Outcome<2>, RunError> {
    run_2d_observed(
        scene,
        &mut |r, _| {
            if r.step > 0 {
                on_step(r)
            }
        },
        None,
    )
}

/// Runs a 1D scene and returns its particles too.
pub fn run_1d(scene: &Scene, on_step: &mut dyn FnMut(&StepReport)) -> Result<Outcome<1>, RunError> {
    run_1d_observed(
        scene,
        &mut |r, _| {
            if r.step > 0 {
                on_step(r)
            }
        },
        None,
    )
}

fn run_2d_observed(
    scene: &Scene,
    on_step: &mut Observer,
    stop: Option<&AtomicBool>,
) -> Result<Outcome<2>, RunError> {
    let (basis, domain) = setup::domain_2d(scene)?.take_basis();
    let bodies = scene.bodies.len();
    match (basis, scene.body_contact()) {
        (Basis2d::Ps(basis), false) => run_with(scene, domain.with_basis(basis), on_step, stop),
        (Basis2d::Linear(basis), false) => run_with(scene, domain.with_basis(basis), on_step, stop),
        (Basis2d::Ps(basis), true) => {
            let basis = PerBody::new(basis, bodies);
            run_with(scene, domain.with_basis(basis), on_step, stop)
        }
        (Basis2d::Linear(basis), true) => {
            let basis = PerBody::new(basis, bodies);
            run_with(scene, domain.with_basis(basis), on_step, stop)
        }
    }
}

fn run_1d_observed(
    scene: &Scene,
    on_step: &mut Observer,
    stop: Option<&AtomicBool>,
) -> Result<Outcome<1>, RunError> {
    let (basis, domain) = setup::domain_1d(scene)?.take_basis();
    let bodies = scene.bodies.len();
    match (basis, scene.body_contact()) {
        (Basis1d::Bspline(basis), false) => {
            run_with(scene, domain.with_basis(basis), on_step, stop)
        }
        (Basis1d::Linear(basis), false) => run_with(scene, domain.with_basis(basis), on_step, stop),
        (Basis1d::Bspline(basis), true) => {
            let basis = PerBody::new(basis, bodies);
            run_with(scene, domain.with_basis(basis), on_step, stop)
        }
        (Basis1d::Linear(basis), true) => {
            let basis = PerBody::new(basis, bodies);
            run_with(scene, domain.with_basis(basis), on_step, stop)
        }
    }
}

/// Set up, step, summarise.
fn run_with<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    domain: Domain<B>,
    on_step: &mut Observer,
    stop: Option<&AtomicBool>,
) -> Result<Outcome<D>, RunError>
where
    Particles<f64, D>: AsParticlesRef,
{
    let mut run = setup::set_up::<D, B>(scene, domain)?;
    let tally = step_loop(scene, &mut run, on_step, stop);
    Ok(summarise(scene, run, tally))
}

/// What the loop gathers over the steps.
struct Tally {
    tracked: Vec<Tracked>,
    /// The energy balance and the condition estimates.
    verdict: Verdict,
    lumped: usize,
    deactivated: usize,
    extended: usize,
    phases: PhaseTimes,
    rms: exact::RmsPositionError,
    failure: Option<StepError>,
    interrupted: bool,
    seconds: f64,
    max_rotation: f64,
    /// The largest rotation of the particles of the paper's non-objective law.
    max_rotation_non_objective: f64,
    /// Particles per occupied element at the start.
    sampling: f64,
    /// The worst-sampled body at the start.
    sampled: Sampled,
    /// The body with the largest share of thin filled elements at the start
    /// ([`Thin::of`]).
    thin: Option<Thin>,
    /// PL's particles on element edges at the start ([`pl_edge_particles_warning`]).
    on_edges: Option<String>,
    /// A PS body jittered coarsely at the start ([`jitter_warning`]).
    jittered: Option<String>,
    /// [`stray_particles`] at the start.
    stray_at_start: usize,
    /// The number of [`pieces`] at the start.
    pieces_at_start: usize,
    /// [`Spin`] of the particles at the start.
    spin_at_start: Spin,
    /// Each body's lattice stretch ([`lattice_stretch`]), for the arrangement's
    /// checks at the start and at the end.
    stretch: Vec<f64>,
    /// The total energy after the last completed step (the initial one before any).
    last_energy: f64,
    /// The largest strain energy of any step (the start's included).
    max_strain: f64,
    /// The largest `kinetic − kinetic_motion` of a step, with its time and
    /// `kinetic` then ([`unseen_velocity_warning`]).
    unseen: (f64, f64, f64),
    /// The step that deactivated the largest share of the functions with
    /// particles ([`deactivation_warning`]).
    deactivation: Deactivation,
    /// The force deactivation's held rows took over the run.
    held: HeldForce,
}

/// At the step of a run that deactivated the largest share of the functions with
/// particles: the time, the functions deactivated and kept, and the largest `M_ii`.
#[derive(Debug, Clone, Copy, Default)]
pub struct Deactivation {
    /// The time of the step.
    pub time: f64,
    /// Functions with particles the strategy deactivated.
    pub deactivated: usize,
    /// Functions with particles it kept.
    pub active: usize,
    /// The largest diagonal mass `M_ii` of the step.
    pub largest_mass: f64,
}

impl Deactivation {
    fn share(&self) -> f64 {
        self.deactivated as f64 / (self.deactivated + self.active).max(1) as f64
    }
}

/// Over a run, the share of the force on the functions that deactivation's held
/// rows took ([`MassReport::held_force_share`](crate::mass::MassReport::held_force_share)):
/// summed over the steps, and the largest with its time.
#[derive(Debug, Clone, Copy, Default)]
pub struct HeldForce {
    /// The sum of every step's share.
    pub sum: f64,
    /// The steps summed.
    pub steps: usize,
    /// The largest share and its time.
    pub largest: (f64, f64),
}

impl HeldForce {
    fn observe(&mut self, share: f64, time: f64) {
        self.sum += share;
        self.steps += 1;
        if share > self.largest.0 {
            self.largest = (share, time);
        }
    }
    /// The share averaged over the run.
    fn mean(&self) -> f64 {
        self.sum / self.steps.max(1) as f64
    }
}

/// Share of the force on the functions that the rows deactivation holds at zero
/// may take, averaged over a run's steps, before the run warns
/// ([`deactivation_warning`]): a user's damped column (1 × 30 blocks of 0.1 ×
/// 0.05, 4 × 4 particles per block, `deactivate:0.01`) hung from 8 deactivated
/// functions at its top that took 18 % of the load (19 % at rest), and settled
/// 0.0258 of the exact 0.0491 with its top particles in tension, judged stable;
/// the seeds' column (`column-large`, 1 × 10 blocks) 2.5 % (at most 10 %, E_u
/// 2.51e-3).
pub const HELD_FORCE_SHARE: f64 = 0.05;

/// Share of the functions with particles that deactivation may remove at a step
/// before a run warns ([`deactivation_warning`]): the seeds' columns lose at most
/// 2 of 51 (`mpm-cli run column-large --mass deactivate`), a user's disk held on a
/// frictionless slope lost 18 % from the first step, a falling block that rebounded
/// in mid-air 10 % or more from t = 0.08.
pub const DEACTIVATED_SHARE: f64 = 0.1;

/// The warning for a run whose deactivation (`spec`, an absolute threshold on
/// `M_ii`) removed [`DEACTIVATED_SHARE`] or more of the functions with particles
/// at some step. A deactivated function takes zero velocity, so at a moving body's
/// edge it holds the body as a wall would. Users' runs judged stable
/// (`deactivate:0.01`, the thesis's threshold, for its columns' masses): a block
/// of density 1 falling freely kept 12 of 39 functions and moved 2.7e-6 in 0.3 s
/// instead of 0.44; a block of density 100 fell until the functions below it were
/// deactivated (14 of 108 at t = 0.1) and rebounded in mid-air; a PL disk on a
/// frictionless slope, 18 % of its functions deactivated, stayed put.
pub fn deactivation_warning(at: &Deactivation, held: &HeldForce, spec: &str) -> Option<String> {
    use crate::scene::limits::echo_significant;
    if held.mean() >= HELD_FORCE_SHARE && at.share() < DEACTIVATED_SHARE {
        return Some(format!(
            "deactivation (`{spec}`, an absolute threshold on the diagonal mass M_ii) held rows with particles at zero velocity that took {:.0} % of the force on the functions over the run ({:.0} % at t = {}): the particles on them are held as by a wall, so a body hangs from them or rests on them (a user's damped column hung from the 8 functions at its top, which took 19 % of the load, and settled 0.0258 of the exact 0.0491 with its top in tension), and the verdict does not see it; take the default mass strategy (`--mass default`), which keeps those functions",
            100.0 * held.mean(),
            100.0 * held.largest.0,
            echo_significant(held.largest.1, 4),
        ));
    }
    (at.deactivated > 0 && at.share() >= DEACTIVATED_SHARE).then(|| {
        format!(
            "at t = {} deactivation (`{spec}`, an absolute threshold on the diagonal mass M_ii, the thesis's for its columns' masses) removed {} of the {} functions with particles ({:.0} %): a deactivated function takes zero velocity, so at a moving body's edge it holds the body as a wall would (users' bodies judged stable: a block falling freely rebounded in mid-air as the functions below it were deactivated, a disk on a frictionless slope with 18 % of its functions deactivated stayed put), and the verdict does not see it; the largest M_ii then was {}: a threshold well below the masses (`deactivate:{}`) keeps the body's functions, but brings back the nearly empty ones it removes (the consistent mass's failure); for a body moving through a mostly empty mesh take the default mass strategy",
            echo_significant(at.time, 5),
            at.deactivated,
            at.deactivated + at.active,
            100.0 * at.share(),
            echo_significant(at.largest_mass, 3),
            echo_significant(at.largest_mass * 1e-3, 1),
        )
    })
}

/// Share of the energy scale above which the kinetic energy of the particle
/// velocities that move no particle (`kinetic − kinetic_motion`) is warned about.
pub const UNSEEN_KINETIC: f64 = 0.05;

/// The warning for a run in which, at some step, the particles' velocities carried
/// more than [`UNSEEN_KINETIC`] of the energy scale `scale` beyond the kinetic
/// energy of the motion: `(unseen, time, kinetic)` at the step where it was largest.
/// Measured on a user's block dropped 1 m onto a slip floor (PS, default mass): 424
/// J of `kinetic` against 60 J of motion after the bounce, out of 3 125 J; the block
/// still rebounds to 75 % of its drop's potential energy.
/// `walls`: the scene has walls (fixed or contact), which the message then speaks
/// of; without, of bodies striking each other.
pub fn unseen_velocity_warning(unseen: (f64, f64, f64), scale: f64, walls: bool) -> Option<String> {
    use crate::scene::limits::echo_significant;
    let (extra, time, kinetic) = unseen;
    let held = if walls {
        "a body rebounding from a wall gets most of it back (taking it out at the walls makes impacts plastic: docs/stability.md, \"The walls take no impulse from the particles\")"
    } else {
        "bodies that part after striking each other get most of it back"
    };
    (scale > 0.0 && extra > UNSEEN_KINETIC * scale).then(|| {
        format!(
            "at t = {} the particles' velocities held {} of kinetic energy of which {} ({:.0} % of the energy scale) moved no particle: the update of eq. (18) carries from step to step the velocity the basis does not see (after impacts above all), and `kinetic`, the energy balance and the verdict count it; `kinetic_motion` (diagnostics.csv, --format json) is the kinetic energy of the motion. That energy is held, not lost: {held}",
            echo_significant(time, 5),
            echo_significant(kinetic, 4),
            echo_significant(extra, 4),
            100.0 * extra / scale
        )
    })
}

/// The strain `ρ |g| H / E` of a body's own weight (H its height along `g`) above
/// which a run warns: far beyond the small strains the elastic laws model, and most
/// often a unit slip (`young` in MPa or kPa instead of Pa).
pub const SELF_WEIGHT_STRAIN: f64 = 0.5;

/// The warning for a body whose own weight would strain it by more than
/// [`SELF_WEIGHT_STRAIN`]: per body (`body_sizes`, the numbers of particles of the
/// bodies in order; empty: one body), the largest `ρ_p |g| H / E_p` over its
/// particles, `ρ_p` and `E_p` each particle's, `H` the body's height along `g`:
/// `heights[b]` where the scene gives it (the extent of the body's region along
/// an axis-aligned `g`), else the extent of its particles' centres plus the mean
/// spacing (`√V⁰_p`, `V⁰_p` in 1D) of its lowest and highest particle, so that a
/// lattice filling a box of height 1 measures about 1, not the 1 less a spacing
/// between its outer centres (1.0052 for cells of 0.025 × 0.0125: a user asked
/// why a column of height 1 was said to be 1.0052 high). The
/// worst body is named where there are several (bodies side by side, or one
/// above another, each measured by its own height). `law_of(p)` names the
/// particle's law, which the message speaks of.
pub fn self_weight_warning<const D: usize>(
    gravity: Option<&[f64]>,
    particles: &Particles<f64, D>,
    body_sizes: &[usize],
    heights: &[Option<f64>],
    material: &impl crate::materials::ParticleMaterials<f64, D>,
    law_of: impl Fn(usize) -> crate::scene::MaterialModel,
) -> Option<String> {
    use crate::scene::MaterialModel;
    let g = gravity?;
    // `hypot`: `|g|` of a huge `g` (1e300) is itself, not an overflow to infinity.
    let g_norm = g.iter().fold(0.0f64, |a, c| a.hypot(*c));
    if g_norm.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) || particles.is_empty() {
        return None;
    }
    let along = |p: usize| (0..D).map(|k| particles.x0[p][k] * g[k]).sum::<f64>() / g_norm;
    let spacing = |p: usize| particles.volume0[p].powf(1.0 / D as f64);
    let sizes = if !body_sizes.is_empty() && body_sizes.iter().sum::<usize>() == particles.len() {
        body_sizes.to_vec()
    } else {
        vec![particles.len()]
    };
    // (strain, particle, height, body) of the worst body.
    let mut worst: Option<(f64, usize, f64, usize)> = None;
    let mut first = 0;
    for (b, &size) in sizes.iter().enumerate() {
        let range = first..first + size;
        first += size;
        if size == 0 {
            continue;
        }
        let ((low, p_low), (high, p_high)) = range
            .clone()
            .map(|p| (along(p), p))
            .fold(((f64::INFINITY, 0), (f64::NEG_INFINITY, 0)), |(l, h), s| {
                (if s.0 < l.0 { s } else { l }, if s.0 > h.0 { s } else { h })
            });
        let height = heights
            .get(b)
            .copied()
            .flatten()
            .unwrap_or_else(|| high - low + 0.5 * (spacing(p_low) + spacing(p_high)));
        let Some((strain, p)) = range
            .map(|p| {
                let e = material.elastic(p);
                (e.density * g_norm * height / e.young, p)
            })
            .max_by(|a, b| a.0.total_cmp(&b.0))
        else {
            continue;
        };
        if worst.is_none_or(|w| strain > w.0) {
            worst = Some((strain, p, height, b));
        }
    }
    let (strain, p, height, body) = worst?;
    (strain > SELF_WEIGHT_STRAIN).then(|| {
        let e = material.elastic(p);
        let law = match law_of(p) {
            MaterialModel::LinearElastic => {
                "and beyond what the `linear-elastic` law models".to_string()
            }
            MaterialModel::Corotational => {
                "and beyond what the `corotational` law models".to_string()
            }
            MaterialModel::NeoHookean => "the `neo-hookean` law takes them, but a body crushed to a fraction of its height by its own weight is seldom what was meant".to_string(),
        };
        let who = if sizes.len() > 1 {
            format!("body {} of {}'s own weight would strain it", body + 1, sizes.len())
        } else {
            "the body's own weight would strain it".to_string()
        };
        format!(
            "{who} by about ρ |g| H / E = {strain:.1e} (ρ = {}, |g| = {}, H = {} along g, E = {}), far beyond small strains ({law}): check the units of `young` (Pa), `density` (kg/m³) and `g` (m/s²)",
            echo_number(e.density),
            echo_number(g_norm),
            echo_fixed(height, 4),
            echo_number(e.young)
        )
    })
}

/// A density from which a material is a solid of metal, rock, concrete or soil in
/// kg/m³ ([`dense_gel_warning`]).
pub const DENSE_SOLID: f64 = 1500.0;
/// The P-wave speed below which such a dense material is as soft as a gel: steel
/// with `young` in MPa (2.1e5) runs at 5.2 m/s, concrete (3e4 MPa) at 4 m/s, the
/// softest clays in Pa at about 25 m/s.
pub const GEL_WAVE_SPEED: f64 = 10.0;

/// The first body whose material and P-wave speed `√((λ + 2μ)/ρ)` pass `test`:
/// how a warning names it ("the material" for one body, "body 2's material"
/// among several), its material and that speed.
fn first_material_where(
    scene: &Scene,
    test: impl Fn(&crate::scene::MaterialSpec, f64) -> bool,
) -> Option<(String, &crate::scene::MaterialSpec, f64)> {
    (0..scene.bodies.len()).find_map(|b| {
        let (m, speed) = (scene.body_material(b), scene.body_wave_speed(b));
        test(m, speed).then(|| {
            let who = if scene.bodies.len() > 1 {
                format!("body {}'s material", b + 1)
            } else {
                "the material".to_string()
            };
            (who, m, speed)
        })
    })
}

/// The warning for a body as dense as a metal, rock or soil in kg/m³ whose P-wave
/// speed `√((λ + 2μ)/ρ)` is that of a gel: most often `young` in MPa or kPa beside
/// `density` in kg/m³ (a user's steel cantilever with E = 2.1e5 sagged until it
/// left the mesh, told to add a wall).
pub fn dense_gel_warning(scene: &Scene) -> Option<String> {
    let (who, m, speed) = first_material_where(scene, |m, speed| {
        m.density >= DENSE_SOLID && speed < GEL_WAVE_SPEED
    })?;
    Some(format!(
        "{who} is as dense as a metal, rock or soil in kg/m³ (density = {}) and as soft as a gel (young = {:e}: a P-wave speed of {speed:.1} m/s, where steel has about 5900 and soils 100 or more): if `young` is in MPa, write it in Pa ({:e} here: × 1e6), in kPa × 1e3",
        echo_number(m.density),
        m.young,
        m.young * 1e6,
    ))
}

/// The warning for a geostatic stress over bodies of several densities of which
/// some are Gmsh bodies: a Gmsh body has no region the other bodies' weight can be
/// integrated over, so it starts with its own density times the depth, and a layer
/// under a lighter or heavier one starts out of equilibrium (a user's two Gmsh
/// layers: +20 % at the bottom, a heave of 5 mm, where the same layers as boxes
/// start exact).
pub fn layered_gmsh_geostatic_warning(scene: &Scene) -> Option<String> {
    use crate::scene::{BodyShape, EffectSpec};
    let geostatic = scene
        .effects
        .iter()
        .any(|e| matches!(e, EffectSpec::GeostaticStress { .. }));
    let gmsh: Vec<String> = scene
        .bodies
        .iter()
        .enumerate()
        .filter(|(_, b)| b.shape == BodyShape::Gmsh)
        .map(|(i, _)| format!("body[{i}]"))
        .collect();
    (geostatic && scene.layered() && !gmsh.is_empty()).then(|| {
        format!(
            "the geostatic stress of a Gmsh body ({}) is its own density times the depth below `surface`, without the weight of the other bodies above it: with bodies of several densities a layer starts out of equilibrium and moves (a user's two Gmsh layers started 20 % off at the bottom and heaved 5 mm); give the layers as `box` or `polygon` bodies, whose stress counts the layers above",
            gmsh.join(", ")
        )
    })
}

/// Changes of element per particle over a run above which a piecewise-linear run
/// warns of grid crossing ([`grid_crossing_warning`]).
pub const PL_CROSSINGS: f64 = 0.5;

/// The share of the energy scale under which the largest strain energy of a run
/// counts as none: its particles crossed element edges without a stress whose
/// force could jump there ([`grid_crossing_warning`] is then not given; a user's
/// freely falling bar was warned of grid crossing with its strain 0 at every
/// step).
pub const STRESS_FREE: f64 = 1e-9;

/// The warning for a piecewise-linear run (`pl`, `pl1d`, `two_d` for the first)
/// whose particles changed element `changes` times in all, `particles` of them,
/// [`PL_CROSSINGS`] per particle or more: a PL function's gradient jumps at the
/// element edges, so that a particle crossing one sees its stress's force change
/// at once, an error that more elements at the same particles per element do not
/// reduce. Measured on a user's 1D bar hanging under gravity (L = 1, E = 1000,
/// ρ = 1, g = 9.81, 4 particles per element, `courant` 0.5, the tip's mean
/// displacement over three periods against the static sag 4.905e-3): PL on 10,
/// 20, 40, 80 elements −0.9, +6.8, +17, +23 % (0, 0.9, 1.6, 3.8 changes per
/// particle); on 80 elements with E = 20000, where no particle crosses, −0.03 %;
/// the B-spline basis +0.03 % on 80.
pub fn grid_crossing_warning(changes: u64, particles: usize, two_d: bool) -> Option<String> {
    let per_particle = changes as f64 / particles.max(1) as f64;
    (particles > 0 && per_particle >= PL_CROSSINGS).then(|| {
        let smooth = if two_d { "ps,pl" } else { "bspline,pl1d" };
        format!(
            "the particles changed element {changes} times ({per_particle:.1} per particle): a piecewise-linear function's gradient jumps at element edges, so each crossing changes at once the force a particle's stress gives (grid crossing), an error in the displacements and stresses that refining the mesh at the same particles per element does not reduce (more particles cross): a 1D bar hanging under gravity sagged 6.8, 17 and 23 % too far on 20, 40 and 80 elements as its particles crossed more often, 0.03 % with the B-spline basis; to see what it does here, run the smooth basis beside it (`mpm-cli compare FILE --basis {smooth}`)"
        )
    })
}

/// The warning for contact between bodies on a piecewise-linear basis with a mass
/// other than `lumped`: the contact forces are sized on lumped rows, and nearly
/// consistent rows spread them further, so they can do positive work.
///
/// On a smooth basis the same holds for the strategies that lump no rows
/// (`consistent`, `extended`, `deactivate`): two PS disks meeting at ±1 m/s
/// gained from 126 to 466 with `extended` and stopped, while the default (whose
/// rows at the bodies' surfaces are lumped), `partial`, `fmpm:2` and `lumped`
/// kept them within 1.2–2 %.
pub fn body_contact_warning(scene: &Scene) -> Option<String> {
    use crate::bases::BasisKind;
    use crate::mass::MassKind;
    let linear = matches!(scene.basis, BasisKind::Pl | BasisKind::Pl1d);
    let unlumped = matches!(
        scene.mass,
        MassKind::Consistent | MassKind::Extended { .. } | MassKind::Deactivate { .. }
    );
    if scene.body_contact() && !linear && unlumped {
        return Some(format!(
            "contact between bodies with the `{}` mass, which lumps no rows: the contact forces are sized on lumped rows, and consistent rows spread them further, so they can add energy (two PS disks meeting at ±1 m/s gained from 126 to 466 with `extended` and stopped; the default kept them within 1.2 %); use the default mass strategy (`--mass default`, its rows at the bodies' surfaces lumped) or `lumped` (docs/scenes.md, the `body-contact` effect)",
            scene.mass.spec()
        ));
    }
    (scene.body_contact() && linear && scene.mass != MassKind::Lumped).then(|| {
        format!(
            "contact between bodies with the `{}` basis and the `{}` mass: the contact forces are sized on lumped rows, and this mass's nearly consistent rows spread them further, so they can add energy (two slow disks gained 26 %, two 1D bars striking at 1 m/s 98 %); use `mass = \"lumped\"` (`--mass lumped`), with which the same bars part at e = 0.89, or the smooth basis (`{}`) (docs/scenes.md, the `body-contact` effect)",
            scene.basis.name(),
            scene.mass.spec(),
            if scene.dim == 1 { "bspline" } else { "ps" }
        )
    })
}

/// Particles per occupied element at the start below which a run warns that its
/// bodies are sampled by about one particle per element or fewer.
pub const SPARSE_SAMPLING: f64 = 1.5;

/// The warning for a fixed `time.dt` that does not divide `time.t_end`: the run
/// takes the nearest whole number of steps, so it ends before or after `t_end`
/// (a step `courant` sets is shortened to end exactly there instead).
fn end_time_warning(scene: &Scene, dt: f64, steps: usize) -> Option<String> {
    let t_end = scene.time.t_end;
    scene.time.dt?;
    let ends = steps as f64 * dt;
    ((ends - t_end).abs() > 1e-9 * t_end).then(|| {
        format!(
            "time.dt = {} does not divide t_end = {}: the run takes {} of {} and ends at t = {}, {} {} it ({} % of t_end); for t_end itself use dt = t_end / {} = {:e}",
            crate::scene::limits::echo_number(dt),
            crate::scene::limits::echo_number(t_end),
            crate::scene::limits::plural(steps, "step", "steps"),
            crate::scene::limits::echo_number(dt),
            crate::scene::limits::echo_significant(ends, 12),
            crate::scene::limits::echo_significant((ends - t_end).abs(), 4),
            if ends > t_end { "after" } else { "before" },
            crate::scene::limits::echo_significant(100.0 * (ends - t_end).abs() / t_end, 3),
            steps,
            t_end / steps as f64,
        )
    })
}

/// The keys that set the particles per element of `scene`'s bodies, for the fixes
/// the warnings give: a Gmsh body takes `subdivide`, the others `per_block`,
/// `count` or `spacing` (and `--particles`).
pub fn particle_keys(scene: &Scene) -> &'static str {
    let gmsh = scene
        .bodies
        .iter()
        .filter(|b| b.shape == crate::scene::BodyShape::Gmsh)
        .count();
    if gmsh == 0 {
        "`per_block`, `count` or `spacing`; `--particles`"
    } else if gmsh == scene.bodies.len() {
        "`per_triangle` and `subdivide` of the Gmsh bodies"
    } else {
        "`per_block`, `count` or `spacing`, and `per_triangle` and `subdivide` of the Gmsh bodies; `--particles`"
    }
}

/// The worst-sampled body at the start, as the sampling warnings name it.
#[derive(Debug, Clone, PartialEq)]
pub struct Sampled {
    /// Its particles per element of the mesh under it ([`BodySampling::per_element`]).
    pub value: f64,
    /// `(body, bodies)` where the bodies are sampled differently; `None` for one
    /// body or bodies sampled alike (within [`SAMPLING_ALIKE`]).
    body: Option<(usize, usize)>,
    sampling: BodySampling,
}

/// Bodies whose particles per element differ by less than this factor are
/// sampled alike: the sampling warnings speak of "the bodies".
pub const SAMPLING_ALIKE: f64 = 1.1;

impl Sampled {
    /// The worst-sampled of `bodies` (the first of equals).
    pub fn of(bodies: &[BodySampling]) -> Self {
        let worst = (0..bodies.len())
            .min_by(|&a, &b| bodies[a].per_element().total_cmp(&bodies[b].per_element()))
            .unwrap_or(0);
        let sampling = bodies.get(worst).copied().unwrap_or(BodySampling {
            per_occupied: 0.0,
            volume_over_elements: 1.0,
            filled: 0,
            thin: 0,
            empty: 0,
            whole: None,
        });
        let value = sampling.per_element();
        let alike = bodies
            .iter()
            .all(|b| b.per_element() <= SAMPLING_ALIKE * value && !b.fills_in_part());
        Sampled {
            value,
            body: (bodies.len() > 1 && !alike).then_some((worst, bodies.len())),
            sampling,
        }
    }

    /// One body (or bodies alike) whose particles fill their elements, sampled by
    /// `value` particles per occupied element.
    pub fn uniform(value: f64) -> Self {
        Self::of(&[BodySampling {
            per_occupied: value,
            volume_over_elements: 1.0,
            filled: 0,
            thin: 0,
            empty: 0,
            whole: None,
        }])
    }

    /// "the bodies are sampled by 1.00 particles per occupied element at the start",
    /// naming the body where they differ and saying why where elements between its
    /// particles hold none; `element` names the mesh's elements.
    fn phrase(&self, element: &str, digits: usize) -> String {
        let (who, it, its) = match self.body {
            None => ("the bodies are".to_string(), "them", "their"),
            Some((b, n)) => (format!("body {} of {n} is", b + 1), "it", "its"),
        };
        let value = self.value;
        if self.sampling.fills_in_part() {
            format!(
                "{who} sampled by {value:.digits$} particles per {element} under {it} at the start ({:.2} per {element} holding one of {its} particles, whose total volume is {:.1} times the total size of those {element}s: the {element}s between {its} particles hold none)",
                self.sampling.per_occupied, self.sampling.volume_over_elements
            )
        } else {
            format!(
                "{who} sampled by {value:.digits$} particles per occupied {element} at the start"
            )
        }
    }
}

/// The warning for a body sampled by about one particle per element or fewer at
/// the start ([`Sampled::value`] below [`SPARSE_SAMPLING`]); `keys` from
/// [`particle_keys`].
pub fn sparse_sampling_warning(sampled: &Sampled, keys: &str) -> Option<String> {
    (sampled.value < SPARSE_SAMPLING).then(|| {
        format!(
            "{}: with about one particle per element or fewer, an element holds none as soon as its particle moves out of it (or already, between particles), the functions there get no mass, and a body can come apart while its energy stays bounded (a verdict of stable does not show it), or bend far too stiffly (a cantilever one element thick, `docs/examples/cantilever.toml` with `count = [24, 2]`, 1.2 per element: PS's tip deflection 0.44 of the one at [96, 8], while PL's beam comes apart); use 3 or more particles per element ({keys})",
            sampled.phrase("element", 2)
        )
    })
}

/// A P-wave speed above that of every real solid (diamond: about 18 000 m/s): a
/// material this fast is most often `density` in g/cm³ beside `young` in Pa
/// ([`featherweight_warning`]).
pub const FASTEST_SOLID: f64 = 2.5e4;

/// The warning for a material faster than any solid (a user's steel with
/// `density = 7.85`: 1.85e5 m/s, 483 092 steps and 99 s).
pub fn featherweight_warning(scene: &Scene) -> Option<String> {
    let (who, m, speed) = first_material_where(scene, |_, speed| speed > FASTEST_SOLID)?;
    // A Poisson's ratio near ½ makes the P-wave fast whatever the density: the
    // bar speed `√(E/ρ)` then tells the two apart (a user's ν = 0.4999999 with
    // E = 5e6 and ρ = 1000, 70.7 m/s along a bar and 9.1e4 m/s as a P-wave, was
    // told to write the density in kg/m³).
    let bar = (m.young / m.density).sqrt();
    if bar <= FASTEST_SOLID {
        return Some(format!(
            "{who} has a P-wave speed √((λ + 2μ)/ρ) of {speed:.2e} m/s, {:.0} times its bar speed √(E/ρ) = {bar:.3e} m/s: with poisson = {} it is nearly incompressible (λ grows as 1/(1 − 2ν)), which makes the time step that small; take `poisson` of 0.49 or less unless the incompressibility is the point (the step grows as √(1 − 2ν) there; at 0.49 the P-wave is {:.1} times the bar speed)",
            speed / bar,
            echo_number(m.poisson),
            ((1.0 - 0.49) / ((1.0 + 0.49) * (1.0 - 0.98f64))).sqrt()
        ));
    }
    Some(format!(
        "{who} has a P-wave speed of {speed:.2e} m/s (young = {:e}, density = {}), faster than any solid (steel about 5 900, diamond 18 000), which makes the time step that small: if `density` is in g/cm³, write it in kg/m³ ({} here: × 1000)",
        m.young,
        echo_number(m.density),
        echo_number(m.density * 1e3),
    ))
}

/// The warning for a scene with a `[reference]` and several bodies: the reference
/// describes the first body (its material and extent), while the error is taken
/// over every particle (a user's beam and rubber block against
/// `column-equilibrium`: 0.897, where each body against its own profile gave
/// 0.116 and 0.030).
pub fn reference_bodies_warning(scene: &Scene) -> Option<String> {
    (scene.reference.is_some() && scene.bodies.len() > 1).then(|| {
        format!(
            "the `[reference]` describes one body, the first (its material and extent), but the error is taken over the particles of all {} bodies, which it does not describe: give the reference a scene of one body",
            scene.bodies.len()
        )
    })
}

/// The warning for a 2D scene measured against a 1D reference (`vibrating-bar`,
/// `column-self-weight`: the bar's `E_u` with `c = √(E/ρ)`) with a Poisson's ratio
/// other than 0: the 2D body is then stiffer than the bar the reference describes
/// (a user's confined block in its first P-wave mode, ν = 0.25: E_u 2.93e-5
/// against the reference, where the errors against its own exact mode were
/// 2.9e-7 with PS and 1.5e-8 with PL; recomputed with `√(E/ρ)` the reference
/// gave 2.932e-5 exactly).
pub fn reference_poisson_warning(scene: &Scene) -> Option<String> {
    use crate::scene::Reference;
    let name = match scene.reference {
        Some(Reference::VibratingBar { .. }) => "vibrating-bar",
        Some(Reference::ColumnSelfWeight {}) => "column-self-weight",
        _ => return None,
    };
    let nu = scene.body_material(0).poisson;
    // The faces along the bar's axis (x for the bar, y for the column): held
    // across it on a block mesh when walls there fix that component (or the
    // normal), and then the body is in uniaxial strain; free, in plane strain with
    // the faces free (a user's bar with free faces: periods 1/1.048 of the
    // reference's at ν = 0.3, which is 1/√(1 − ν²)).
    use crate::scene::Component;
    let (faces, across) = match scene.reference {
        Some(Reference::VibratingBar { .. }) => (["bottom", "top"], Component::Y),
        _ => (["left", "right"], Component::X),
    };
    let held = faces.iter().all(|face| scene.side_holds(face, across));
    (scene.dim == 2 && nu != 0.0).then(|| {
        let (how, factor) = if held {
            (
                "held at its faces, its P-wave speed √((λ + 2μ)/ρ) is",
                ((1.0 - nu) / ((1.0 + nu) * (1.0 - 2.0 * nu))).sqrt(),
            )
        } else {
            (
                "with its faces free, a slender bar's wave speed √(E/((1 − ν²)ρ)) is about",
                1.0 / (1.0 - nu * nu).sqrt(),
            )
        };
        format!(
            "the `{name}` reference is the 1D bar's, with the wave speed √(E/ρ) of uniaxial stress; with poisson = {} this 2D body is stiffer ({how} {factor:.3} times that), and the error measures that difference as well: set `poisson = 0` to compare with the reference",
            echo_number(nu),
        )
    })
}

/// Each body's lattice stretch ([`crate::arrangement::body_stretch`]): its largest
/// lattice spacing over the mean; 1 for a body sampled from a Gmsh surface.
pub(crate) fn lattice_stretch(scene: &Scene) -> Vec<f64> {
    scene
        .bodies
        .iter()
        .map(|body| {
            if body.shape == crate::scene::BodyShape::Gmsh {
                return 1.0;
            }
            let h: Option<Vec<f64>> = (0..scene.dim)
                .map(|k| scene.lattice_spacing(body, k))
                .collect();
            h.map_or(1.0, |h| crate::arrangement::body_stretch(&h))
        })
        .collect()
}

/// The share of the particles on element edges at the start from which a PL run
/// warns ([`pl_edge_particles_warning`]).
pub const PL_EDGE_SHARE: f64 = 0.1;

/// The warning for a PL run with a body of which [`PL_EDGE_SHARE`] or more of the
/// particles lie on element edges or vertices at the start (`bodies`: per body,
/// those particles and all its particles; the first such body named where there
/// are several): PL's gradient jumps
/// there and each such particle takes one side's, which biases the internal force.
/// Square lattices on blocks of four triangles put half their particles on the
/// block diagonals (`per_block = [4, 4]`: 8 of 16). Measured on a user's standing
/// P-wave mode (a 1 × 0.5 block, walls holding x at the ends and y on the faces,
/// E = 1000, ν = 0.25, ρ = 1, to 2.25 periods; `mpm-cli run FILE --basis pl
/// --blocks B --particles P --out DIR`, `E_u` against the exact mode): 4 × 4 per
/// block 1.04e-5, 8.54e-6, 8.43e-6 on 8 × 4, 16 × 8, 32 × 16 blocks (the
/// amplitude 18 % low, the period 4.7 % long), 3 × 4 (none on an edge) 2.35e-7,
/// 5.58e-8, 1.47e-8 (order 2).
pub fn pl_edge_particles_warning(bodies: &[(usize, usize)], default_mass: bool) -> Option<String> {
    let share = |(on, n): (usize, usize)| n > 0 && on as f64 >= PL_EDGE_SHARE * n as f64;
    let warned: Vec<usize> = (0..bodies.len()).filter(|&b| share(bodies[b])).collect();
    let first = *warned.first()?;
    let (on, n) = bodies[first];
    let percent = 100.0 * on as f64 / n as f64;
    let who = match (bodies.len(), warned.len()) {
        (1, _) => format!("{on} of the {n} particles ({percent:.0} %)"),
        (_, 1) => format!(
            "{on} of the {n} particles of body {} ({percent:.0} %)",
            first + 1
        ),
        (_, 2) => format!(
            "{on} of the {n} particles of body {} ({percent:.0} %; one other body likewise)",
            first + 1
        ),
        (_, k) => format!(
            "{on} of the {n} particles of body {} ({percent:.0} %; {} other bodies likewise)",
            first + 1,
            k - 1
        ),
    };
    // The default gives a vertex whose particles all lie on the edges opposite it
    // the velocity of its neighbours (`Role::Ghost`); every other strategy holds it
    // at zero (measured 2026-12-08 on a user's two disks translating at (0.1, 0.1)
    // along the diagonals with `lumped`: strain where none should be, and the
    // momentum moved from 1e-15 to 3.8e-5 at step 9).
    let held = if default_mass {
        ""
    } else {
        "; with this mass strategy (all but the default) a vertex whose only particles lie on the edges opposite it has no mass and is held at zero velocity, which strains the particles beside it and moves the bodies' momentum (two disks translating along the block diagonals with `lumped`: momentum 3.8e-5 where it was 1e-15): the default mass strategy gives such a vertex the velocity of its neighbours"
    };
    Some(format!(
        "{who} lie on element edges or vertices at the start (a lattice whose rows fall on the triangles' edges: a square one on blocks of four triangles has half its particles on the block diagonals): PL's gradient jumps there and each such particle takes one side's, which biases the internal force (a block vibrating in its first P-wave mode at `per_block = [4, 4]`: amplitude 18 % low, period 4.7 % long, an error that did not fall with the mesh; at [3, 4], with no particle on an edge, order 2); give a lattice whose rows miss the edges (`per_block` with one odd and one even count, such as [3, 4] or [5, 4]; `jitter` moves the particles off the edges but measured no better), or the smooth basis `ps`{held}"
    ))
}

/// Particles per occupied element at the start above which a run warns that the
/// mesh, not the particles, sets its error: B4's error on h = 0.25 falls from 16 to
/// 260 particles per element and then holds (1.96e-4 at 260, 1.9644e-4 at 1040;
/// `docs/results.md`); the ladder study itself runs at 1040–1130.
pub const DENSE_SAMPLING: f64 = 2500.0;

/// The warning for bodies sampled by `sampling` particles per occupied element at
/// the start, if that is above [`DENSE_SAMPLING`]; `keys` from [`particle_keys`].
pub fn dense_sampling_warning(sampling: f64, keys: &str) -> Option<String> {
    (sampling > DENSE_SAMPLING).then(|| {
        format!(
            "the bodies are sampled by {sampling:.0} particles per occupied element at the start: the step's cost grows with the particles, but beyond a few hundred per element the error is set by the mesh (B4 on h = 0.25: 1.96e-4 at 260, 1.96e-4 at 1040); for accuracy refine the mesh (`blocks` or `edge_length`) and give a few dozen particles per element ({keys})"
        )
    })
}

/// The angular momentum of the particles about their centre of mass (2D; zero in
/// 1D), `L = Σ_p m_p (x_p − x_c) × (v_p − v_c)`, and the most that their motion
/// relative to the centre could hold, `R = Σ_p m_p |x_p − x_c| |v_p − v_c|`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Spin {
    /// `L`.
    pub angular_momentum: f64,
    /// `R ≥ |L|`.
    pub bound: f64,
}

impl Spin {
    /// The spin of `particles`.
    pub fn of<const D: usize>(particles: &Particles<f64, D>) -> Spin {
        let total: f64 = particles.mass.iter().sum();
        if D != 2 || total.is_nan() || total <= 0.0 {
            return Spin::default();
        }
        let (mut xc, mut vc) = ([0.0; 2], [0.0; 2]);
        for p in 0..particles.len() {
            for k in 0..2 {
                xc[k] += particles.mass[p] * particles.x[p][k] / total;
                vc[k] += particles.mass[p] * particles.v[p][k] / total;
            }
        }
        let mut spin = Spin::default();
        for p in 0..particles.len() {
            let r = [particles.x[p][0] - xc[0], particles.x[p][1] - xc[1]];
            let w = [particles.v[p][0] - vc[0], particles.v[p][1] - vc[1]];
            spin.angular_momentum += particles.mass[p] * (r[0] * w[1] - r[1] * w[0]);
            spin.bound += particles.mass[p] * r[0].hypot(r[1]) * w[0].hypot(w[1]);
        }
        spin
    }
}

/// Share of its angular momentum about the centre of mass that a spinning body
/// may lose over a run, in a scene that exerts no torque on it, before the run
/// warns.
pub const SPIN_LOSS: f64 = 0.05;

/// The warning for bodies that lost more than [`SPIN_LOSS`] of their angular
/// momentum about their centre of mass (`start` and `end`) in a scene that exerts
/// no torque about it: no fixed or slip boundaries and no effect but uniform
/// gravity and body forces and contact between the bodies. Only a rotation that is
/// a tenth or more of the motion relative to the centre (`|L| ≥ 0.1 R`) is judged.
/// The verdict judges energy, which a lost rotation keeps as strain: PS with
/// `lumped` took a free plate from L = 15.7 to 0.4 and was judged stable.
/// `sampling`: particles per occupied element at the start, which decides
/// whether too few particles can be the cause named (a teacher's disk of radius
/// 0.08 in blocks of 1 with PL, about 100 particles per triangle, lost 18 % of its
/// angular momentum and 85 % of its turn, and was told to give more particles).
pub fn spin_loss_warning(scene: &Scene, start: Spin, end: Spin, sampling: f64) -> Option<String> {
    use crate::scene::EffectSpec;
    let torque_free = scene.boundaries.iter().all(|b| b.fix.is_empty())
        && scene.effects.iter().all(|e| {
            matches!(
                e,
                EffectSpec::Gravity { .. }
                    | EffectSpec::BodyForce { .. }
                    | EffectSpec::BodyContact {}
            )
        });
    let l0 = start.angular_momentum;
    let spinning = l0.abs() >= 0.1 * start.bound && l0 != 0.0;
    let lost = (l0 - end.angular_momentum) / l0;
    (torque_free && spinning && lost.abs() > SPIN_LOSS).then(|| {
        let fix = if matches!(
            scene.mass,
            crate::mass::MassKind::Lumped | crate::mass::MassKind::Partial(_)
        ) {
            "lumped rows damp a rotation (PS `lumped` lost 97 % of a plate's in half a turn, PL `lumped` 14 % of a disk's); the default mass strategy keeps it (remove `mass`, or `--mass default`)".to_string()
        } else if sampling < PS_SAMPLING {
            format!("fewer than about 3 particles per triangle let whole elements damp it; give more particles per element ({})", particle_keys(scene))
        } else if scene.basis == crate::bases::BasisKind::Pl {
            "PL's default lumps the rows of the functions a body covers in part with a share of the plain term (its affine term vanishes on linear triangles), which damps a rotation, most of all that of a body within one or two elements (a disk of radius 0.05 in blocks of 1 turned 0.048 rad of 2.4): PS's default keeps such a rotation (`basis = \"ps\"`: 2.3999 rad), or refine the mesh so that the body spans several elements".to_string()
        } else {
            "the default's lumped rows at the body's edge damp it where an element's particles do not determine an affine field (docs/stability.md, \"A spinning square's angular momentum\"): more particles per element, or a mesh the body spans by several elements, keep it".to_string()
        };
        format!(
            "the bodies' angular momentum about their centre of mass went from {l0:.4e} to {:.4e} ({:.0} % {}), although nothing in the scene exerts a torque about it: the rotation turned into strain or was damped, which the energy verdict does not see; {fix}",
            end.angular_momentum,
            100.0 * lost.abs(),
            if lost > 0.0 { "lost" } else { "gained" },
        )
    })
}

/// Particles per occupied triangle at the start below which a PS run warns that its
/// error can grow with refinement.
pub const PS_SAMPLING: f64 = 3.0;

/// The warning for a PS body sampled by fewer than [`PS_SAMPLING`] particles per
/// triangle (and not already below [`SPARSE_SAMPLING`]).
/// Measured on `scenes/column-large.toml` (default mass, `--courant 0.5`), 3 × 3
/// particles per block (2.25 per triangle) on 1 × 10, 2 × 20, 4 × 40 blocks:
/// UNSTABLE, then det F failures at steps 2441 and 3057; 6 × 6 per block: stable,
/// E_u 2.7e-4, 1.2e-4, 1.1e-4.
///
/// `keys` from [`particle_keys`].
pub fn ps_sampling_warning(sampled: &Sampled, keys: &str) -> Option<String> {
    (SPARSE_SAMPLING..PS_SAMPLING).contains(&sampled.value).then(|| {
        let edges = if sampled.sampling.fills_in_part() {
            ""
        } else {
            "; a body whose edges cut triangles fills those in part, which lowers this average below what its lattice gives inside: place its edges on block lines, or give more per block"
        };
        format!(
            "{}, fewer than the 3 a PS triangle needs (each holds 9 functions, quadratic on its Powell–Sabin sub-triangles): the sums over particles no longer integrate them, and the error can grow as the mesh is refined (B5b's column with 2.25 per triangle fails on 2 × 20 and 4 × 40 blocks, with 9 per triangle its E_u falls to 1.1e-4); use 3 or more per triangle ({keys}; `per_block` 4 × 4 on block meshes){edges}",
            sampled.phrase("triangle", 2)
        )
    })
}

/// A lattice's `jitter` at or above which a PS body sampled by fewer than
/// [`JITTER_SAMPLING`] particles per triangle is warned about (`jitter_warning`).
pub const JITTER_WARNED: f64 = 0.2;

/// Particles per occupied triangle from which a jittered PS body's sums hold
/// (`jitter_warning`).
pub const JITTER_SAMPLING: f64 = 9.0;

/// The warning for a PS body whose lattice is jittered by [`JITTER_WARNED`] or
/// more of its cell with fewer than [`JITTER_SAMPLING`] particles per occupied
/// triangle: sums over particles at random points integrate the quadratic pieces
/// with errors that fall only as the count grows. Measured on a user's damped
/// column under its weight (1 × 30 blocks of 0.1 × 0.05, E = 1e5, to t = 2; top
/// settlement against the exact 0.04905, largest σ_yy error): unjittered at 4 × 4
/// per block (4 per triangle) +1.1 %, 0.17; jitter 0.1 +2.2 %, 0.29; jitter 0.3
/// +13.7 %, 0.69; jitter 0.3 at 6 × 6 (9 per triangle) +1.8 %, 0.28, and at 8 × 8
/// +0.5 %, 0.18.
fn jitter_warning(scene: &Scene, bodies: &[BodySampling]) -> Option<String> {
    let (b, body, sampling) = scene
        .bodies
        .iter()
        .zip(bodies)
        .enumerate()
        .find(|(_, (body, s))| body.jitter >= JITTER_WARNED && s.per_occupied < JITTER_SAMPLING)
        .map(|(b, (body, s))| (b, body, s))?;
    let who = if scene.bodies.len() > 1 {
        format!("body[{b}]")
    } else {
        "the body".to_string()
    };
    Some(format!(
        "{who}'s lattice is jittered by {} of its cell and samples each occupied triangle by {:.1} particles: sums over particles at random points integrate the PS functions' quadratic pieces with errors that fall only as the count grows (a user's column under its weight settled 13.7 % too far at jitter 0.3 with 4 per triangle, 2.2 % at jitter 0.1, and 1.8 % and 0.5 % at jitter 0.3 with 9 and 16; unjittered, 1.1 %); with a jitter of {} give 8 × 8 or more per block of four triangles (16 per triangle) for a static answer within 1 % (`body[{b}].{}`), or a jitter of 0.1 or less (docs/results.md, \"Jittered particles\")",
        crate::scene::limits::echo_number(body.jitter),
        sampling.per_occupied,
        crate::scene::limits::echo_number(body.jitter),
        body.lattice_key(),
    ))
}

/// Filled elements holding fewer than 3 (`driver::failure::THIN_ELEMENT`) particles, at or above
/// this share of a body's filled elements, make a PS run warn ([`Thin`]).
pub const THIN_SHARE: f64 = 0.25;

/// Filled elements a body needs for its share of thin ones to count ([`Thin`]): a
/// beam one element thick (`docs/examples/cantilever.toml`) has 3, one of them a
/// small triangle of the `polygon` mesh that no lattice point falls in.
pub const THIN_LEAST_FILLED: usize = 10;

/// Elements a body that fills its elements whole (edges on element edges,
/// `BodySampling::whole`) needs for its share of thin ones to count ([`Thin`]):
/// a body of 2 × 2 or 3 × 3 blocks has no element or 8 whose every neighbour
/// holds its particles (fewer than [`THIN_LEAST_FILLED`]), and all of its 16 or 36
/// elements are inside it.
pub const THIN_LEAST_WHOLE: usize = 4;

/// A body whose filled elements are thin in part although its average per
/// element is enough ([`ps_sampling_warning`] is silent): a lattice of 3 × 4 per
/// block of four triangles, 3 per triangle on average, puts 2 in the left and
/// right triangles of every block. Measured (`docs/examples/p-wave-block.toml`,
/// PS, default mass): E_u 3.17e-5 at 3 × 4 per block against 6.20e-7 at 4 × 4 (4
/// in every triangle, counting those on the diagonals in both), 2.25e-6 at 4 × 3
/// (2 in the top and bottom triangles) and 1.56e-6 at 5 × 4 (none thin); a
/// user's P-wave block ran with its period 8.7 % long at 3 × 4.
#[derive(Debug, Clone, Copy)]
pub struct Thin {
    /// `(body, bodies)`.
    body: (usize, usize),
    thin: usize,
    filled: usize,
    empty: usize,
}

impl Thin {
    /// The body with the largest share of thin filled elements, if that share is
    /// [`THIN_SHARE`] or more (of the bodies with [`THIN_LEAST_FILLED`] filled
    /// elements or more).
    pub fn of(bodies: &[BodySampling]) -> Option<Self> {
        // `(thin, filled, empty)` of a body: its elements inside it, or for a
        // small body that fills its elements whole, all of them.
        let counted = |b: &BodySampling| {
            if b.filled >= THIN_LEAST_FILLED {
                return Some((b.thin, b.filled, b.empty));
            }
            b.whole
                .filter(|&(filled, _)| filled >= THIN_LEAST_WHOLE)
                .map(|(filled, thin)| (thin, filled, 0))
        };
        let share = |(thin, filled, _): (usize, usize, usize)| thin as f64 / filled.max(1) as f64;
        let (b, (thin, filled, empty)) = bodies
            .iter()
            .enumerate()
            .filter_map(|(b, body)| counted(body).map(|c| (b, c)))
            .max_by(|(_, a), (_, b)| share(*a).total_cmp(&share(*b)))?;
        (share((thin, filled, empty)) >= THIN_SHARE && thin > 0).then_some(Thin {
            body: (b, bodies.len()),
            thin,
            filled,
            empty,
        })
    }

    /// The warning, `keys` from [`particle_keys`].
    pub fn warning(&self, keys: &str) -> String {
        let who = match self.body {
            (_, 1) => "the body".to_string(),
            (b, n) => format!("body {} of {n}", b + 1),
        };
        format!(
            "{} of the {} triangles inside {who} hold fewer than 3 particles ({:.0} %{}), although it has 3 or more per triangle on average: how a lattice falls on the triangles decides how many each holds (on blocks of four triangles 3 × 4 per block puts 2 in the left and right triangles of every block, 4 × 3 in the top and bottom ones, and a lattice of 4 per block out of step with the blocks, as the lattice a disk centres on itself can be, 2 or fewer in some); each PS triangle holds 9 functions, quadratic on its Powell–Sabin sub-triangles, which 2 particles integrate poorly (a block in its first P-wave mode, docs/examples/p-wave-block.toml: E_u 3.17e-5 at `per_block = [3, 4]`, 6.20e-7 at [4, 4], 1.56e-6 at [5, 4]); give 3 or more in every triangle ({keys}; on block meshes a square `per_block` such as [4, 4] or [6, 6], or for a disk a spacing of a quarter block with its `centre` on a block corner or centre, which puts its lattice in step with the blocks (a disk of radius 0.25 at [1.0, 1.2] on blocks of 0.125 with spacing 0.03125 leaves 10 of its 30 triangles thin, at [1.0, 1.25] none); non-square ones such as [5, 4] leave PS 2–8 times less accurate than [4, 4] on the same block; PL wants one odd and one even count, so compare the two bases each on its own lattice)",
            self.thin,
            self.filled,
            100.0 * self.thin as f64 / self.filled.max(1) as f64,
            if self.empty > 0 {
                format!(
                    "; {} of them none: a lattice coarse along an axis, one particle per block, leaves the triangles beside its rows empty",
                    self.empty
                )
            } else {
                String::new()
            }
        )
    }
}

/// The tracked particles: the particle nearest each of the scene's tracked points.
fn tracked<const D: usize, B: Basis<f64, D>>(scene: &Scene, run: &Prepared<D, B>) -> Vec<Tracked> {
    // The initial positions: the particles' reference positions.
    let (positions, steps) = (&run.driver.particles.x0, run.steps);
    let exact = if run.solution.is_some_and(|s| s.has_history()) {
        steps
    } else {
        0
    };
    scene
        .output
        .tracked
        .iter()
        .map(|t| {
            let d = |p: usize| {
                (0..D)
                    .map(|k| (positions[p][k] - t[k]).powi(2))
                    .sum::<f64>()
            };
            let particle = (0..positions.len())
                .min_by(|&a, &b| d(a).total_cmp(&d(b)))
                .unwrap_or(0);
            Tracked {
                particle,
                x0: std::array::from_fn(|k| if k < D { positions[particle][k] } else { 0.0 }),
                time: Vec::with_capacity(steps),
                velocity: Vec::with_capacity(steps),
                displacement: Vec::with_capacity(steps),
                exact_displacement: Vec::with_capacity(exact),
                exact_velocity: Vec::with_capacity(exact),
            }
        })
        .collect()
}

/// A warning for each tracked point of the scene that lies more than two particle
/// spacings (`V_p^(1/D)`) from the particle it picks (the nearest): a point outside
/// every body tracks a particle the user did not mean.
fn tracked_warnings<const D: usize>(
    scene: &Scene,
    particles: &Particles<f64, D>,
    tracked: &[Tracked],
) -> Vec<String> {
    scene
        .output
        .tracked
        .iter()
        .zip(tracked)
        .enumerate()
        .filter_map(|(k, (point, t))| {
            let p = t.particle;
            let distance = (0..D)
                .map(|i| (particles.x0[p][i] - point[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            let spacing = particles.volume0.get(p)?.powf(1.0 / D as f64);
            (distance > 2.0 * spacing).then(|| {
                format!(
                    "output.tracked[{k}] at {} lies {distance:.3e} from the particle it tracks (particle {p} at {}, the nearest; {} particle spacings away): put the point inside a body",
                    crate::driver::point(&point[..D]),
                    crate::driver::point(&t.x0[..D]),
                    echo_fixed(distance / spacing, 1)
                )
            })
        })
        .collect()
}

/// Shows `on_step` the initial state, then takes the steps (until the first
/// failure), recording the tracked particles and the energy and mass facts.
fn step_loop<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    run: &mut Prepared<D, B>,
    on_step: &mut Observer,
    stop: Option<&AtomicBool>,
) -> Tally
where
    Particles<f64, D>: AsParticlesRef,
{
    let mut tracked = tracked(scene, run);
    let (solution, origin) = (run.solution, run.origin);
    let driver = &mut run.driver;
    let start = driver.report();
    // The initial state (step 0); the public entry points other than
    // `observe_2d`/`observe_1d` pass only steps > 0 on.
    on_step(&start, driver.particles.view());
    let mut verdict = Verdict::new(&start).with_initial_stress_energy(
        crate::diagnostics::initial_stress_energy(&driver.particles, driver.material()),
    );
    let mut last_energy = start.total_energy();
    let mut max_strain = start.strain;
    let (mut lumped, mut deactivated, mut extended) = (0usize, 0usize, 0usize);
    let mut phases = PhaseTimes::default();
    let mut rms = exact::RmsPositionError::default();
    let mut failure = None;
    let sampling = driver.particles_per_occupied_element();
    let regions: Vec<Option<crate::setup::regions::Region>> = scene
        .bodies
        .iter()
        .map(|b| crate::setup::regions::Region::of(b, scene.dim))
        .collect();
    let bodies = driver.sampling_by_body(&run.body_sizes, &|b, x| {
        let mut p = [0.0; 2];
        p[..x.len().min(2)].copy_from_slice(&x[..x.len().min(2)]);
        regions
            .get(b)
            .and_then(Option::as_ref)
            .is_some_and(|r| !r.contains(p))
    });
    let sampled = Sampled::of(&bodies);
    let thin = Thin::of(&bodies);
    let jittered = (scene.basis == crate::bases::BasisKind::Ps)
        .then(|| jitter_warning(scene, &bodies))
        .flatten();
    let on_edges = (scene.basis == crate::bases::BasisKind::Pl)
        .then(|| {
            pl_edge_particles_warning(
                &driver.particles_on_element_edges(&run.body_sizes),
                scene.mass == crate::mass::MassKind::default(),
            )
        })
        .flatten();
    let stretch = lattice_stretch(scene);
    let at_start = fragments(&driver.particles, &run.body_sizes, &stretch);
    let (stray_at_start, pieces_at_start) = (at_start.stray, at_start.pieces.len());
    let spin_at_start = Spin::of(&driver.particles);
    let mut max_rotation = crate::material::max_rotation(&driver.particles.f);
    let mut max_rotation_non_objective = driver
        .material()
        .max_rotation_of_non_objective(&driver.particles.f, max_rotation);
    let mut interrupted = false;
    let mut unseen = (0.0f64, 0.0, 0.0);
    let mut deactivation = Deactivation::default();
    let mut held = HeldForce::default();
    let clock = std::time::Instant::now();
    for _ in 0..run.steps {
        if stop.is_some_and(|s| s.load(Ordering::Relaxed)) {
            interrupted = true;
            break;
        }
        let r = match driver.step() {
            Ok(r) => r,
            Err(e) => {
                failure = Some(e);
                break;
            }
        };
        for t in &mut tracked {
            t.time.push(r.time);
            t.velocity.push(from_vec(&driver.particles.v[t.particle]));
            t.displacement
                .push(from_vec(&driver.particles.u[t.particle]));
            if let Some(s) = solution.filter(|s| s.has_history()) {
                t.exact_displacement
                    .push(s.displacement(t.x0, origin, D, r.time));
                t.exact_velocity.push(s.velocity(t.x0, origin, D, r.time));
            }
        }
        if let Some(Solution::AxisAligned(a)) = solution {
            let parts = &driver.particles;
            for p in 0..parts.len() {
                let x0 = from_vec(&parts.x0[p]);
                rms.add_sample(a.position(x0, r.time), from_vec(&parts.x[p]));
            }
            rms.finish_step();
        }
        if r.step % ROTATION_EVERY == 0 {
            if let Some(at) = collapsed(driver) {
                on_step(&r, driver.particles.view());
                verdict.observe(&r);
                let reason = collapse_reason(driver, at, r.time, unstable(&verdict));
                failure = Some(StepError::Collapsed {
                    step: r.step,
                    reason,
                });
                last_energy = r.total_energy();
                break;
            }
            let now = crate::material::max_rotation(&driver.particles.f);
            max_rotation = max_rotation.max(now);
            max_rotation_non_objective = max_rotation_non_objective.max(
                driver
                    .material()
                    .max_rotation_of_non_objective(&driver.particles.f, now),
            );
        }
        on_step(&r, driver.particles.view());
        verdict.observe(&r);
        last_energy = r.total_energy();
        max_strain = max_strain.max(r.strain);
        if r.kinetic - r.kinetic_motion > unseen.0 {
            unseen = (r.kinetic - r.kinetic_motion, r.time, r.kinetic);
        }
        lumped = lumped.max(r.mass_report.lumped_rows);
        deactivated = deactivated.max(r.mass_report.deactivated);
        let now = Deactivation {
            time: r.time,
            deactivated: r.mass_report.deactivated,
            active: r.mass_report.active,
            largest_mass: r.mass_report.largest_mass,
        };
        if now.share() > deactivation.share() {
            deactivation = now;
        }
        held.observe(r.mass_report.held_force_share, r.time);
        extended = extended.max(r.mass_report.extended);
        phases.evaluate += r.phases.evaluate;
        phases.assemble += r.phases.assemble;
        phases.solve += r.phases.solve;
        phases.update += r.phases.update;
    }
    if failure.is_none() && !interrupted {
        // A particle the last step carried out of the mesh: no next step finds it.
        failure = driver.check_in_mesh().err();
    }
    Tally {
        tracked,
        verdict,
        lumped,
        deactivated,
        extended,
        phases,
        rms,
        failure,
        interrupted,
        seconds: clock.elapsed().as_secs_f64(),
        max_rotation,
        max_rotation_non_objective,
        sampling,
        sampled,
        thin,
        on_edges,
        jittered,
        spin_at_start,
        stretch,
        stray_at_start,
        pieces_at_start,
        last_energy,
        max_strain,
        unseen,
        deactivation,
        held,
    }
}

/// Why the bodies of `driver` collapsed at `time`, `(det F, particle)` from
/// [`collapsed`] ([`crate::material::collapse_reason`]). `unstable`: the energy growth and the time it crossed the verdict's bound,
/// where it did ([`unstable`]).
fn collapse_reason<const D: usize, B: Basis<f64, D>>(
    driver: &setup::SceneDriver<D, B>,
    (j, p): (f64, usize),
    time: f64,
    unstable: Option<(f64, f64)>,
) -> String {
    let x: Vec<f64> = driver.particles.x[p].iter().copied().collect();
    crate::material::collapse_reason(
        j,
        p,
        &crate::driver::point(&x),
        time,
        driver.material().law(p),
        unstable,
    )
}

/// The smallest `det F` and its particle, when it is below
/// [`crate::material::COLLAPSED_JACOBIAN`]: the bodies collapsed.
fn collapsed<const D: usize, B: Basis<f64, D>>(
    driver: &setup::SceneDriver<D, B>,
) -> Option<(f64, usize)> {
    let (j, p) = crate::material::min_jacobian(&driver.particles.f);
    (j < crate::material::COLLAPSED_JACOBIAN).then_some((j, p))
}

/// The time-centred growth of the energy and the time it crossed the verdict's
/// bound, if it has.
fn unstable(verdict: &Verdict) -> Option<(f64, f64)> {
    let (_, crossed) = verdict.growth_crossed?;
    verdict
        .energy_bound_broken()
        .then(|| (verdict.centred_growth(), crossed))
}

/// The error against the reference solution at the end of the run.
fn error<const D: usize, B: Basis<f64, D>>(
    run: &Prepared<D, B>,
    rms: &exact::RmsPositionError,
) -> Option<f64> {
    let (driver, origin) = (&run.driver, run.origin);
    let parts = &driver.particles;
    run.solution.and_then(|s| match s {
        // Paper eq. (47) needs at least one step.
        Solution::AxisAligned(_) => (rms.steps() > 0).then(|| rms.value()),
        Solution::Equilibrium {
            height,
            density,
            gravity,
            young,
            at_reference,
        } => {
            let sigma_base = (height * density * gravity).abs();
            let worst = (0..parts.len())
                .map(|p| {
                    let exact = if at_reference {
                        // Started from the geostatic state (its particles carry
                        // `σ⁰`, so the law alone does not give the settled height
                        // of a point), or a neo-Hookean column (whose profile in
                        // the current height is not the linear law's: a user's
                        // soft column was measured against it, 0.335 where the
                        // weight above gave 0.146): the weight above the
                        // particle's reference height, whatever the law.
                        let y0 = parts.x0[p][D - 1] - origin[D - 1];
                        exact::bar_equilibrium_stress_at_reference(y0, height, density, gravity)
                    } else {
                        let y = parts.x[p][D - 1] - origin[D - 1];
                        exact::bar_equilibrium_stress_linear(y, height, density, gravity, young)
                    };
                    (parts.sigma[p][(D - 1, D - 1)] - exact).abs() / sigma_base
                })
                .fold(0.0, f64::max);
            Some(worst)
        }
        _ => {
            // Thesis eq. (4.4): E_u = sqrt(Σ_p V_p |û_p − u(x_p⁰, t)|²).
            let mut err2 = 0.0;
            for p in 0..parts.len() {
                let exact = s.displacement(from_vec(&parts.x0[p]), origin, D, driver.time());
                let d2: f64 = (0..D).map(|k| (parts.u[p][k] - exact[k]).powi(2)).sum();
                err2 += parts.volume[p] * d2;
            }
            Some(err2.sqrt())
        }
    })
}

/// What a growth of the time-centred total above [`STABLE_ENERGY_GROWTH`],
/// with no failed step, says and what to do about it: when it
/// crossed the bound (`crossed`, step and time, of `steps`), the Courant number
/// `dt / dt_critical` and what to lower (`time.courant` when the step came from it,
/// `from_courant`, else the scene's `time.dt`), and the particles per occupied
/// element against the functions per element. Such a growth builds up over many steps or impacts: it is the time
/// integration's error on the motion, and it falls with the step (on a jittered soft
/// plate dropped on a slip floor the centred growth is 6.9e-2 at `courant` 0.5 and
/// 2.8e-2 at 0.25; a disk thrown at a no-slip post 7.7e-2, 3.0e-2, 1.1e-2 at 0.4,
/// 0.2, 0.1: `docs/stability.md`), and with fewer particles than functions per
/// element it is larger (9.5 % at 3.6 particles per occupied element, 3.8 % with
/// four times as many, measured on the total). The step suggested is the one at
/// which a growth falling in proportion to the step, `growth` now, would be 4 %:
/// the step times `0.04 / growth`, between a quarter and a half of it (a soft block
/// growing 0.104 at `courant = 0.5` grew 5.4e-2 at the 0.25 that halving gave, and
/// held at 0.125, a user found; a growth that rises faster than the step, an
/// instability, is not helped by less than a quarter either).
/// The share of the growth that one step must hold for the growth hint to name
/// that step beside the crossing of the bound.
const RISE_NAMED: f64 = 0.2;

#[allow(clippy::too_many_arguments)]
pub fn energy_growth_hint(
    growth: f64,
    crossed: Option<(usize, f64)>,
    rise: Option<(usize, f64, f64)>,
    steps: usize,
    dt: f64,
    dt_critical: Option<f64>,
    from_courant: bool,
    particles_per_element: f64,
    functions_per_element: usize,
) -> String {
    // Where most of the growth came in one step (an impact) away from the
    // crossing, that step is named too: the crossing can come early, a smaller
    // growth against a smaller energy scale.
    let rise = rise.filter(|&(step, _, share)| {
        share >= RISE_NAMED && crossed.is_none_or(|(crossed, _)| crossed != step)
    });
    let when = match (crossed, rise) {
        (Some((step, time)), None) => {
            format!("it reached the bound at t = {time:.4} (step {step} of {steps}); ")
        }
        (Some((step, time)), Some((at, at_time, share))) => format!(
            "it reached the bound at t = {time:.4} (step {step} of {steps}) and grew most at t = {at_time:.4} (step {at}: {:.0} % of the growth in that step); ",
            100.0 * share
        ),
        (None, Some((at, at_time, share))) => format!(
            "it grew most at t = {at_time:.4} (step {at} of {steps}: {:.0} % of the growth in that step); ",
            100.0 * share
        ),
        (None, None) => String::new(),
    };
    let critical = dt_critical.filter(|c| c.is_finite() && *c > 0.0);
    let factor = if growth.is_finite() && growth > 0.0 {
        (0.04 / growth).clamp(0.25, 0.5)
    } else {
        0.5
    };
    // The step falls by half to a quarter at a time: what the growth would be
    // there, as it is (a growth of 40 % at a quarter of the step is still 10 %).
    let projected = growth * factor;
    let again = if projected > 0.05 {
        "; if it stays above 5 % (the verdict's bound) or does not fall, lower it again"
    } else {
        "; if it does not, lower it again"
    };
    let why = format!(
        "a growth of {growth:.2e} that falls in proportion to the step would be {:.1} % there{again}",
        100.0 * projected
    );
    let step = match (critical, from_courant) {
        (Some(critical), true) => format!(
            "the time step is {:.2} of the critical step estimated at the start: lower `time.courant` (to {:.2}, say: {why}; `--courant` on the command line) or `time.dt`",
            dt / critical,
            dt / critical * factor
        ),
        (Some(critical), false) => format!(
            "the time step `time.dt` = {dt:.3e} is {:.2} of the critical step {critical:.3e} estimated at the start: lower `time.dt` (to {:.3e}, say: {why}; `--dt` on the command line)",
            dt / critical,
            dt * factor
        ),
        (None, true) => "lower `time.courant` (`--courant` on the command line)".to_string(),
        (None, false) => format!(
            "lower `time.dt` (now {dt:.3e}; to {:.3e}, say: {why}; `--dt` on the command line)",
            dt * factor
        ),
    };
    // Below 3 per element (a PS triangle's least, and PL's functions) the
    // sampling is a cause of its own (B5b's column at 2.25 per triangle grows 48 %
    // by step 955); above, more particles helped some impacts and not others.
    let sampling = if particles_per_element < PS_SAMPLING.min(functions_per_element as f64) {
        format!(
            ", or use more particles per element ({particles_per_element:.1} per occupied element at the end, for the {functions_per_element} functions of each; `per_block`, `count` or `spacing`)"
        )
    } else if particles_per_element < functions_per_element as f64 {
        format!(
            "; with {particles_per_element:.1} per occupied element at the end, for the {functions_per_element} functions of each, more particles per element (`per_block`, `count` or `spacing`) lowered the growth of a jittered plate (9.5 % → 3.8 % with four times as many) but not of every impact (a block dropped 2 m onto a slip floor grew 8.4 % at 4 × 4 per block and 10.3 % at 6 × 6): lower the step first"
        )
    } else {
        String::new()
    };
    format!(
        "{when}energy gained without a failed step is the time integration's error on this motion, which falls with the step (to first or second order, depending on the motion: measure it at two steps); {step}{sampling}"
    )
}

/// For a PL run with the default mass whose energy grew: PL's `lumped` held the
/// impacts where the default gained (measured, growth of the time-centred total
/// with the default against `lumped`: a user's disk dropped on a contact floor at
/// `courant = 0.25` (`docs/examples/disk-bounce.toml --basis pl`) 9.2e-2 against
/// 9e-15 (measured 2026-12-07; 0.26 against 2.8e-3 before), `docs/examples/drop-plate.toml` at 0.5 0.165
/// against 0.019; `docs/stability.md`). Not for PS, whose default holds them.
fn pl_lumping_hint(scene: &Scene) -> Option<String> {
    use crate::bases::BasisKind;
    (matches!(scene.basis, BasisKind::Pl | BasisKind::Pl1d) && scene.mass == crate::mass::MassKind::default())
        .then(|| {
            "with PL, `mass = \"lumped\"` (`--mass lumped`) takes some impacts with less gain than PL's default (a disk dropped on a contact floor, `docs/examples/disk-bounce.toml`: 9.2e-2 of the energy scale with the default, 9e-15 with `lumped`) but not every one, nor a body settling under large strains (`docs/examples/block-drop.toml`: 0.18 with the default, 0.07 with `lumped`; PL wants a `courant` of about 0.12 there), or the PS basis, whose default holds them".to_string()
        })
}

/// The fix for contact between bodies on a mass that spreads its forces
/// ([`body_contact_warning`]): `lumped` or a smooth basis on PL, the default mass
/// strategy or `lumped` on a smooth basis.
fn body_contact_fix(scene: &Scene) -> Option<&'static str> {
    body_contact_warning(scene)?;
    Some(
        if matches!(
            scene.basis,
            crate::bases::BasisKind::Pl | crate::bases::BasisKind::Pl1d
        ) {
            "use `mass = \"lumped\"` (`--mass lumped`) or a smooth basis (PS, or `bspline` in 1D)"
        } else {
            "use the default mass strategy (`--mass default`) or `lumped`"
        },
    )
}

/// What the dissipative effects (contact between bodies) added to the energy over
/// the run, `unearned` ([`StepReport::unearned_work`]), when it is at least 1 % of
/// the energy scale `scale`, and the fix: with PL and a mass other than `lumped`
/// the forces sized on lumped rows spread through nearly consistent rows (a user's
/// PL1D bars gained 30 times their energy that way, `docs/scenes.md`).
pub fn unearned_work_hint(scene: &Scene, unearned: f64, scale: f64) -> Option<String> {
    (unearned > 0.0 && unearned >= 0.01 * scale).then(|| {
        let fix = body_contact_fix(scene).unwrap_or("lower the step");
        format!(
            "the contact between bodies added {unearned:.3e} to the energy over the run ({:.0} % of the energy scale), although its forces can only take energy out: it is counted as energy gained, not as work; {fix}",
            100.0 * unearned / scale
        )
    })
}

/// With a fixed `dt`, the steps the watch over the critical step split: the
/// scene's step was above 0.9 of the critical step somewhere
/// ([`crate::setup::watch_thresholds`]), and the run took those steps in sub-steps.
fn split_steps_warning(
    scene: &Scene,
    dt: f64,
    start: Option<f64>,
    watched: Option<crate::driver::WatchReport>,
) -> Option<String> {
    let w = watched.filter(|w| w.split_steps > 0 && scene.time.courant.is_none())?;
    let (lowest, step, time) = w.lowest?;
    let start = start?;
    let (_, trigger) = crate::setup::watch_thresholds(None, dt / start);
    Some(format!(
        "the critical step fell from {} at the start to {} at its lowest (step {step}, t = {}) as the bodies moved over the mesh: `time.dt` = {} was above {} of it in places, so {} taken in up to {} sub-steps at 0.7 of the critical step; give `courant` instead of `dt` to follow the critical step throughout, or a `dt` below {}",
        crate::scene::limits::echo_significant(start, 3),
        crate::scene::limits::echo_significant(lowest, 3),
        crate::scene::limits::echo_significant(time, 4),
        crate::scene::limits::echo_number(dt),
        crate::scene::limits::echo_significant(trigger, 3),
        crate::scene::limits::plural(w.split_steps, "step was", "steps were"),
        w.most_substeps,
        crate::scene::limits::echo_significant(0.9 * lowest, 2),
    ))
}

/// What a condition estimate above [`STABLE_CONDITION`] says about the system the
/// mass strategy `mass` (a [`Summary::mass`] name) solves, and what to do about it.
/// On `docs/examples/drop-plate.toml` to t = 0.3: `lumped` 3.7e19, `partial`
/// 2.7e21, the default 1.9e2.
pub fn condition_hint(mass: &str) -> String {
    let fix = "the default mass strategy (remove `mass`, or `--mass default`) expresses such functions through their neighbours and keeps them out of the system";
    if mass == "lumped" {
        format!(
            "the lumped mass solves exactly, but its condition (the largest function mass over the smallest) says that some function's support holds almost no particle: that function's velocity is the ratio of two tiny numbers, which a particle's round-off or noise can blow up; {fix}"
        )
    } else if mass.starts_with("extended") {
        "the system is nearly singular even after the extension: some solved function's coverage lies just above the threshold below which it is extended (the table's `min_cover`, `worst_coverage` in `--out`'s diagnostics.csv, name it and where it is); raise that threshold (`--mass extended-hybrid:0.05:0.75`, say)".to_string()
    } else {
        format!(
            "the mass system `{mass}` solves is nearly singular: some function's support holds almost no particle (or too few for the functions the elements hold); {fix}"
        )
    }
}

/// The summary and outcome of a run: error, energy drift and growth, the verdict.
fn summarise<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    run: Prepared<D, B>,
    tally: Tally,
) -> Outcome<D> {
    let end = run.driver.report();
    let error = error(&run, &tally.rms);
    let (energy_drift, energy_growth) = tally.verdict.energy_drift_and_growth();
    let failure = tally.failure;
    let max_condition = tally.verdict.max_condition;
    // The last state, if the loop's sampling missed it.
    let failure = failure.or_else(|| {
        collapsed(&run.driver).map(|at| StepError::Collapsed {
            step: run.driver.steps(),
            reason: collapse_reason(&run.driver, at, run.driver.time(), unstable(&tally.verdict)),
        })
    });
    let stable = tally.verdict.stable(failure.is_some());
    let energy_growth_hint =
        (failure.is_none() && tally.verdict.energy_bound_broken()).then(|| {
            energy_growth_hint(
                tally.verdict.centred_growth(),
                tally.verdict.growth_crossed,
                tally.verdict.largest_rise_share(),
                run.driver.steps(),
                run.dt,
                run.dt_critical,
                scene.time.courant.is_some(),
                run.driver.particles_per_occupied_element(),
                run.driver.functions_per_element(),
            )
        });
    // Contact between bodies that added energy: name it before the step.
    // When the contact's energy is most of the growth, a smaller step is no fix
    // (PL1D bars striking each other: ×5 energy at any Courant number) and is not
    // offered.
    let energy_growth_hint = energy_growth_hint.map(|hint| {
        let scale = tally.verdict.scale();
        let unearned = end.unearned_work();
        match unearned_work_hint(scene, unearned, scale) {
            Some(contact) if unearned >= 0.5 * tally.verdict.centred_growth() * scale => contact,
            Some(contact) => format!("{contact}; otherwise: {hint}"),
            None => hint,
        }
    });
    let energy_growth_hint = energy_growth_hint.map(|hint| match pl_lumping_hint(scene) {
        Some(lumping) => format!("{hint}; {lumping}"),
        None => hint,
    });
    let driver = run.driver;
    let watched = driver.watch_report();
    let now = crate::material::max_rotation(&driver.particles.f);
    let max_rotation = tally.max_rotation.max(now);
    // The warning concerns the particles of the paper's non-objective law only.
    let non_objective_rotation = tally.max_rotation_non_objective.max(
        driver
            .material()
            .max_rotation_of_non_objective(&driver.particles.f, now),
    );
    let warnings = crate::material::rotation_warning(non_objective_rotation);
    // A law that is not objective, turned: the spurious strain energy of the
    // rotation is no error of the step, and a smaller step did not help.
    let non_objective = crate::material::non_objective_growth_cause(non_objective_rotation);
    let energy_growth_hint = energy_growth_hint.map(|hint| match &non_objective {
        Some(cause) => format!("{cause}; otherwise: {hint}"),
        None => hint,
    });
    let at_end = fragments(&driver.particles, &run.body_sizes, &tally.stretch);
    let irregularity =
        crate::arrangement::irregularity(&driver.particles, &run.body_sizes, &tally.stretch);
    let keys = particle_keys(scene);
    // Each body's height along an axis-aligned `g`, from its region.
    let heights: Vec<Option<f64>> = {
        let g = scene.gravity();
        let axis = g.as_deref().and_then(|g| {
            let nonzero: Vec<usize> = (0..g.len()).filter(|&k| g[k] != 0.0).collect();
            (nonzero.len() == 1).then(|| nonzero[0])
        });
        scene
            .bodies
            .iter()
            .map(|b| {
                let k = axis?;
                let (lo, hi) = b.bounds()?;
                Some(hi[k] - lo[k])
            })
            .collect()
    };
    let held_by_deactivation = deactivation_warning(
        &tally.deactivation,
        &tally.held,
        &driver.mass_strategy().spec(),
    );
    let self_weight = self_weight_warning(
        scene.gravity().as_deref(),
        &driver.particles,
        &run.body_sizes,
        &heights,
        driver.material(),
        |p| {
            let mut first = 0;
            let body = run
                .body_sizes
                .iter()
                .position(|&n| {
                    first += n;
                    p < first
                })
                .unwrap_or(0);
            scene.body_material(body).model
        },
    );
    Outcome {
        summary: Summary {
            scene: scene.name.clone(),
            basis: scene.basis.name(),
            mass: scene.mass.spec(),
            functions: run.functions,
            particles: driver.particles.len(),
            steps: driver.steps(),
            dt: run.dt,
            // A `courant` run that took all its steps of `t_end / steps` ends at
            // `t_end` itself (the product of the two rounds: 0.7999999999999999).
            t_end: if scene.time.courant.is_some()
                && failure.is_none()
                && !tally.interrupted
                && driver.steps() == run.steps
            {
                scene.time.t_end
            } else {
                driver.time()
            },
            error,
            error_measure: scene.reference.map(|r| r.error_measure(scene.dim)),
            max_lumped_rows: tally.lumped,
            max_deactivated: tally.deactivated,
            max_extended: tally.extended,
            dt_critical: run.dt_critical,
            // The lowest of the start's estimate and the watch's.
            dt_critical_lowest: watched.and_then(|w| {
                w.lowest.map_or(run.dt_critical, |(c, _, _)| {
                    Some(run.dt_critical.map_or(c, |start| start.min(c)))
                })
            }),
            split_steps: watched.map_or(0, |w| w.split_steps),
            most_substeps: watched.map_or(1, |w| w.most_substeps),
            advected_steps: watched.map_or(0, |w| w.advected_steps),
            fastest_speed: watched.and_then(|w| w.fastest.map(|(v, _)| v)),
            courant: scene.time.courant,
            max_condition,
            energy_initial: tally.verdict.initial_energy(),
            // A failed step leaves the particles half updated: the energy is that
            // of the last completed step, which the verdict saw.
            energy_final: if failure.is_some() {
                tally.last_energy
            } else {
                end.total_energy()
            },
            energy_drift,
            energy_growth,
            energy_growth_centred: tally.verdict.centred_growth(),
            energy_scale: tally.verdict.scale(),
            stable,
            energy_growth_hint,
            failure: failure.as_ref().map(|e| {
                // An inverted element or a collapse, which the contact's added
                // energy explains better than the sampling the driver sees.
                let inverted = matches!(
                    e,
                    StepError::NotFinite { .. } | StepError::Collapsed { .. }
                );
                // A failure the driver did not put down to the law, of bodies of
                // a law that is not objective that turned during the run.
                let law = non_objective
                    .as_ref()
                    .filter(|_| inverted && !e.to_string().contains("`linear-elastic`"));
                match (&self_weight, body_contact_fix(scene).filter(|_| inverted)) {
                    // The material's scale first: the step's own advice (a
                    // smaller step, a stiffer wall) does not fit a `young` in MPa.
                    (Some(w), _) => format!(
                        "{w}, which explains this failure before anything the step saw: {e}"
                    ),
                    (None, _) if law.is_some() => format!(
                        "{e}. Before anything else: {}",
                        law.expect("checked")
                    ),
                    (None, Some(fix)) => format!(
                        "{e}. Before anything else: the contact between the bodies with the `{}` mass can add energy (the warning above), which can make a run fail this way; {fix}",
                        scene.mass.spec()
                    ),
                    (None, None) => e.to_string(),
                }
            }),
            max_rotation,
            irregularity,
            warnings: warnings
                .into_iter()
                .chain(run.warnings.iter().cloned())
                .chain(end_time_warning(scene, run.dt, run.steps))
                .chain(split_steps_warning(scene, run.dt, run.dt_critical, watched))
                .chain(self_weight.clone())
                .chain(dense_gel_warning(scene))
                .chain(featherweight_warning(scene))
                .chain(reference_bodies_warning(scene))
                .chain(sparse_sampling_warning(&tally.sampled, keys))
                .chain(tally.on_edges.clone())
                .chain(reference_poisson_warning(scene))
                .chain(dense_sampling_warning(tally.sampling, keys))
                .chain(
                    failure
                        .is_none()
                        .then(|| {
                            spin_loss_warning(
                                scene,
                                tally.spin_at_start,
                                Spin::of(&driver.particles),
                                tally.sampling,
                            )
                        })
                        .flatten(),
                )
                .chain(
                    (scene.basis == crate::bases::BasisKind::Ps)
                        .then(|| ps_sampling_warning(&tally.sampled, keys))
                        .flatten(),
                )
                .chain(
                    (scene.basis == crate::bases::BasisKind::Ps
                        && tally.sampled.value >= PS_SAMPLING)
                        .then(|| tally.thin.as_ref().map(|t| t.warning(keys)))
                        .flatten(),
                )
                .chain(tally.jittered.clone())
                .chain(body_contact_warning(scene))
                .chain(
                    // Particles on the edges flip between the elements there as they
                    // sit: the warning of those speaks of the same jumps.
                    (matches!(
                        scene.basis,
                        crate::bases::BasisKind::Pl | crate::bases::BasisKind::Pl1d
                    ) && tally.on_edges.is_none()
                        // A body that never strained (a free fall) crosses
                        // without a force to jump.
                        && tally.max_strain > STRESS_FREE * tally.verdict.scale())
                    .then(|| {
                        grid_crossing_warning(
                            driver.element_changes(),
                            driver.particles.len(),
                            scene.dim == 2,
                        )
                    })
                    .flatten(),
                )
                .chain(layered_gmsh_geostatic_warning(scene))
                .chain(unseen_velocity_warning(
                    tally.unseen,
                    tally.verdict.scale(),
                    scene.contact_walls() || scene.boundaries.iter().any(|b| !b.fix.is_empty()),
                ))
                .chain(held_by_deactivation.clone())
                .chain(tracked_warnings(scene, &driver.particles, &tally.tracked))
                .chain(crate::arrangement::irregularity_warning(
                    &irregularity,
                    scene.basis == crate::bases::BasisKind::Ps,
                    tally.sampling,
                    scene.contact_walls(),
                ))
                .chain(stray_warning(
                    tally.stray_at_start,
                    at_end.stray,
                    driver.particles.len(),
                ))
                .chain(
                    // After a step that failed numerically the particles lie where
                    // the failure put them; a body that left the mesh in pieces, or
                    // collapsed, is still one to count.
                    (!matches!(
                        failure,
                        Some(
                            StepError::NotFinite { .. } | StepError::MassNotPositiveDefinite { .. }
                        )
                    ))
                    .then(|| {
                        pieces_warning(
                            tally.pieces_at_start,
                            &at_end.pieces,
                            driver.particles.len(),
                        )
                    })
                    .flatten(),
                )
                .collect(),
            interrupted: tally.interrupted,
            held_by_deactivation: held_by_deactivation.is_some(),
            tracked_end: tally
                .tracked
                .iter()
                .filter_map(|t| t.displacement.last().map(|u| (t.x0, *u)))
                .collect(),
            tracked_end_json: tally
                .tracked
                .iter()
                .filter_map(|t| {
                    t.displacement.last().map(|u| TrackedEnd {
                        started_at: t.x0[..scene.dim].to_vec(),
                        displacement: u[..scene.dim].to_vec(),
                    })
                })
                .collect(),
            pieces: [tally.pieces_at_start, at_end.pieces.len()],
            stray: [tally.stray_at_start, at_end.stray],
            seconds: tally.seconds,
            phases: tally.phases,
        },
        particles: driver.particles,
        tracked: tally.tracked,
        failure,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::Vector2;

    /// The vibrating bar's Poisson warning names the wave speed of the faces the
    /// scene gives: held (the built-in, top and bottom fixed in y) or free.
    #[test]
    fn the_poisson_warning_follows_the_bar_s_faces() {
        let mut scene = Scene::builtin("vibrating-bar").unwrap();
        scene.material.poisson = 0.3;
        let held = reference_poisson_warning(&scene).unwrap();
        assert!(
            held.contains("held at its faces, its P-wave speed √((λ + 2μ)/ρ) is 1.160 times"),
            "{held}"
        );
        scene.boundaries.retain(|b| b.tag != "top");
        let free = reference_poisson_warning(&scene).unwrap();
        assert!(free.contains("with its faces free, a slender bar's wave speed √(E/((1 − ν²)ρ)) is about 1.048 times"), "{free}");
    }

    #[test]
    fn velocity_that_moves_no_particle_is_warned_about_above_its_share() {
        assert!(unseen_velocity_warning((4.9, 0.5, 100.0), 100.0, true).is_none());
        let w = unseen_velocity_warning((483.9, 0.49155, 1887.0), 2500.0, true).unwrap();
        assert!(
            w.starts_with("at t = 0.49155 the particles' velocities held 1887 of kinetic energy of which 483.9 (19 % of the energy scale) moved no particle"),
            "{w}"
        );
        assert!(unseen_velocity_warning((1.0, 0.1, 1.0), 0.0, true).is_none());
    }

    /// A warning's fix names the keys the scene's bodies take: `subdivide` for a
    /// Gmsh body (a user was told `per_block`, which a Gmsh body refuses).
    #[test]
    fn the_sampling_fix_names_the_keys_of_the_bodies() {
        let scene = |body: &str| {
            Scene::from_toml(
                &format!("name = \"g\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"gmsh\"\nfile = \"m.msh\"\n[material]\nyoung = 1.0\ndensity = 1.0\n{body}[time]\ndt = 0.1\nt_end = 1.0\n"),
                "g.toml",
            )
            .unwrap()
        };
        let gmsh = "[[body]]\nshape = \"gmsh\"\nfile = \"m.msh\"\nsurface = 1\n";
        let block = "[[body]]\nmin = [0.1, 0.1]\nmax = [0.2, 0.2]\ncount = [2, 2]\n";
        assert_eq!(
            particle_keys(&scene(gmsh)),
            "`per_triangle` and `subdivide` of the Gmsh bodies"
        );
        assert!(particle_keys(&scene(block)).starts_with("`per_block`"));
        let both = particle_keys(&scene(&format!("{gmsh}{block}")));
        assert!(
            both.contains("`per_block`") && both.contains("`subdivide`"),
            "{both}"
        );
        let w =
            sparse_sampling_warning(&Sampled::uniform(1.0), particle_keys(&scene(gmsh))).unwrap();
        assert!(
            w.contains("(`per_triangle` and `subdivide` of the Gmsh bodies)"),
            "{w}"
        );
    }

    /// Steel with its density in g/cm³ is faster than any solid and is warned about
    /// with the density in kg/m³; steel in kg/m³ is not. A reference over several
    /// bodies is warned about; over one it is not.
    #[test]
    fn a_density_in_g_per_cm3_and_a_reference_over_several_bodies_are_warned_about() {
        let mut steel = Scene::builtin("vibrating-bar").unwrap();
        steel.material.young = 2e11;
        steel.material.density = 7850.0;
        steel.bodies.iter_mut().for_each(|b| b.material = None);
        assert!(featherweight_warning(&steel).is_none());
        assert!(reference_bodies_warning(&steel).is_none());
        steel.material.density = 7.85;
        let w = featherweight_warning(&steel).expect("g/cm³");
        assert!(w.contains("write it in kg/m³ (7850 here"), "{w}");
        let mut two = steel.clone();
        two.bodies.push(two.bodies[0].clone());
        let w = reference_bodies_warning(&two).expect("two bodies");
        assert!(w.contains("all 2 bodies"), "{w}");
        // Nearly incompressible rubber in kg/m³: the Poisson's ratio is named, not
        // the density (a user's finding).
        let mut rubber = steel.clone();
        rubber.material.young = 5e6;
        rubber.material.density = 1000.0;
        rubber.material.poisson = 0.4999999;
        let w = featherweight_warning(&rubber).expect("ν near ½");
        assert!(
            w.contains("with poisson = 0.4999999 it is nearly incompressible")
                && w.contains("take `poisson` of 0.49 or less")
                && !w.contains("g/cm³"),
            "{w}"
        );
    }

    /// A 2D scene with a Poisson's ratio measured against a 1D reference is warned
    /// about; the built-in B2 (ν = 0) and a 1D bar are not.
    #[test]
    fn a_one_dimensional_reference_for_a_body_with_poisson_is_warned_about() {
        let mut bar = Scene::builtin("vibrating-bar").unwrap();
        assert!(reference_poisson_warning(&bar).is_none());
        bar.material.poisson = 0.25;
        bar.bodies.iter_mut().for_each(|b| b.material = None);
        let w = reference_poisson_warning(&bar).expect("ν = 0.25");
        assert!(w.contains("is 1.095 times that"), "{w}");
        assert!(reference_poisson_warning(&Scene::builtin("vibrating-bar-1d").unwrap()).is_none());
    }

    /// A material as dense as steel and as soft as a gel is warned about (`young`
    /// in MPa beside `density` in kg/m³); steel in Pa, a soft clay in Pa and a
    /// unitless teaching scene are not.
    #[test]
    fn young_in_mpa_beside_a_density_in_kg_per_m3_is_warned_about() {
        let scene = |young: f64, density: f64| {
            Scene::from_toml(
                &format!("name = \"u\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"blocks\"\nx = [0.0, 1.0]\ny = [0.0, 1.0]\nblocks = [2, 2]\n[material]\nyoung = {young:e}\ndensity = {density:e}\n[[body]]\nmin = [0.0, 0.0]\nmax = [1.0, 0.5]\ncount = [2, 2]\n[time]\ndt = 0.1\nt_end = 1.0\n"),
                "u.toml",
            )
            .unwrap()
        };
        let w = dense_gel_warning(&scene(2.1e5, 7850.0)).expect("steel in MPa");
        assert!(
            w.contains("a P-wave speed of 5.2 m/s") && w.contains("write it in Pa (2.1e11 here"),
            "{w}"
        );
        assert!(dense_gel_warning(&scene(2.1e11, 7850.0)).is_none());
        assert!(dense_gel_warning(&scene(1e6, 1800.0)).is_none());
        assert!(dense_gel_warning(&scene(100.0, 1.0)).is_none());
    }

    /// Gmsh layers of two densities under a geostatic stress are warned about; box
    /// layers, or Gmsh bodies of one density, are not.
    #[test]
    fn gmsh_layers_under_a_geostatic_stress_are_warned_about() {
        let scene = |bodies: &str| {
            Scene::from_toml(
                &format!("name = \"g\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"blocks\"\nx = [0.0, 1.0]\ny = [0.0, 2.0]\nblocks = [2, 4]\n[material]\nyoung = 1e6\ndensity = 1000.0\n{bodies}[[effect]]\nkind = \"gravity\"\ng = [0.0, -10.0]\n[[effect]]\nkind = \"geostatic-stress\"\nsurface = 2.0\n[time]\ndt = 1e-4\nt_end = 1e-3\n"),
                "g.toml",
            )
            .unwrap()
        };
        let gmsh = |density: f64| {
            format!("[[body]]\nshape = \"gmsh\"\nfile = \"m.msh\"\nsurface = 1\nmaterial = {{ young = 1e6, density = {density:?} }}\n")
        };
        let boxed = |y0: f64, density: f64| {
            format!("[[body]]\nmin = [0.0, {y0:?}]\nmax = [1.0, {:?}]\ncount = [2, 2]\nmaterial = {{ young = 1e6, density = {density:?} }}\n", y0 + 1.0)
        };
        let w = layered_gmsh_geostatic_warning(&scene(&format!(
            "{}{}",
            gmsh(2000.0),
            boxed(1.0, 1000.0)
        )));
        assert!(
            w.as_deref()
                .is_some_and(|w| w.starts_with("the geostatic stress of a Gmsh body (body[0])")),
            "{w:?}"
        );
        assert!(layered_gmsh_geostatic_warning(&scene(&format!(
            "{}{}",
            boxed(0.0, 2000.0),
            boxed(1.0, 1000.0)
        )))
        .is_none());
        assert!(layered_gmsh_geostatic_warning(&scene(&format!(
            "{}{}",
            gmsh(1000.0),
            gmsh(1000.0)
        )))
        .is_none());
    }

    #[test]
    fn sampling_far_above_the_studies_is_warned_about() {
        assert!(
            dense_sampling_warning(1130.0, "keys").is_none(),
            "the B4 ladder's sampling"
        );
        let w = dense_sampling_warning(250_000.0, "keys").unwrap();
        assert!(w.contains("250000 particles per occupied element"), "{w}");
        assert!(w.contains("refine the mesh"), "{w}");
    }

    /// A neo-Hookean box of height 1 (a 10 × 10 lattice of spacing 0.1, centres
    /// from 0.05 to 0.95) is measured 1 tall, and the warning speaks of its own law
    /// (a user's: "H = 0.875" for a box 1 tall, and the `linear-elastic` and
    /// `corotational` laws named for a neo-Hookean body).
    #[test]
    fn the_self_weight_warning_measures_the_body_and_names_its_law() {
        use crate::material::{Elastic, NeoHookean};
        use crate::scene::MaterialModel;
        let x: Vec<Vector2<f64>> = (0..100)
            .map(|i| Vector2::new(0.05 + 0.1 * (i % 10) as f64, 0.05 + 0.1 * (i / 10) as f64))
            .collect();
        let particles = Particles::<f64, 2>::new(x, vec![0.01; 100], 1.0);
        let soft = NeoHookean::new(Elastic::new(10.0, 0.3, 1.0).unwrap(), 2);
        let warn = |law: MaterialModel| {
            self_weight_warning(Some(&[0.0, -10.0]), &particles, &[], &[], &soft, |_| law).unwrap()
        };
        let neo = warn(MaterialModel::NeoHookean);
        assert!(neo.contains("ρ |g| H / E = 1.0e0"), "{neo}");
        assert!(neo.contains("H = 1.0000 along g"), "{neo}");
        assert!(neo.contains("the `neo-hookean` law takes them"), "{neo}");
        assert!(!neo.contains("corotational"), "{neo}");
        let linear = warn(MaterialModel::LinearElastic);
        assert!(
            linear.contains("beyond what the `linear-elastic` law models"),
            "{linear}"
        );
        // Two bodies, one above the other: each measured by its own height and
        // named (as one body the pair would be 1 tall).
        let softer = NeoHookean::new(Elastic::new(8.0, 0.3, 1.0).unwrap(), 2);
        let two = self_weight_warning(
            Some(&[0.0, -10.0]),
            &particles,
            &[50, 50],
            &[],
            &softer,
            |_| MaterialModel::NeoHookean,
        )
        .unwrap();
        assert!(
            two.starts_with(
                "body 1 of 2's own weight would strain it by about ρ |g| H / E = 6.2e-1"
            ),
            "{two}"
        );
        assert!(two.contains("H = 0.5000 along g"), "{two}");
        // Stiff enough (strain 0.4): no warning.
        let stiff = NeoHookean::new(Elastic::new(25.0, 0.3, 1.0).unwrap(), 2);
        assert!(
            self_weight_warning(Some(&[0.0, -10.0]), &particles, &[], &[], &stiff, |_| {
                MaterialModel::NeoHookean
            })
            .is_none()
        );
    }

    /// PL with the default mass is pointed to `lumped` when its energy grew;
    /// PS, and PL with a strategy of its own, are not.
    #[test]
    fn pl_with_the_default_is_pointed_to_lumping_when_its_energy_grew() {
        use crate::bases::BasisKind;
        use crate::mass::MassKind;
        let ps = Scene::builtin("column-small").unwrap();
        assert!(pl_lumping_hint(&ps).is_none());
        let mut pl = ps.clone().with_basis(BasisKind::Pl).unwrap();
        pl.mass = MassKind::default();
        assert!(pl_lumping_hint(&pl).unwrap().contains("`--mass lumped`"));
        pl.mass = MassKind::Lumped;
        assert!(pl_lumping_hint(&pl).is_none());
    }

    /// The hint of an energy growth says when the bound was crossed, the Courant
    /// number and half of it, and asks for more particles only where an element
    /// holds fewer than its functions. A scene with a fixed `dt` is told to lower
    /// `dt`, not `courant`, which it does not give.
    #[test]
    fn the_energy_growth_hint_fits_the_step_and_the_sampling() {
        let sparse = energy_growth_hint(
            0.06,
            Some((120, 0.25)),
            None,
            400,
            1e-3,
            Some(2e-3),
            true,
            4.5,
            9,
        );
        for part in [
            "it reached the bound at t = 0.2500 (step 120 of 400)",
            "the time step is 0.50 of the critical step",
            "lower `time.courant` (to 0.25, say: a growth of 6.00e-2 that falls in proportion to the step would be 3.0 % there; if it does not, lower it again",
            "4.5 per occupied element at the end, for the 9 functions of each",
        ] {
            assert!(sparse.contains(part), "`{part}` not in: {sparse}");
        }
        // A growth the largest cut leaves above the bound says so (a PL column at
        // 0.5: 40 % at 0.12 would still be 10 %).
        let steep = energy_growth_hint(0.4, None, None, 400, 1e-3, Some(2e-3), true, 12.0, 3);
        assert!(
            steep.contains("(to 0.12, say: a growth of 4.00e-1 that falls in proportion to the step would be 10.0 % there; if it stays above 5 % (the verdict's bound) or does not fall, lower it again"),
            "{steep}"
        );
        let dense = energy_growth_hint(0.06, None, None, 400, 1e-3, None, false, 12.0, 3);
        assert!(!dense.contains("per occupied element"), "{dense}");
        assert!(
            dense.contains("lower `time.dt` (now 1.000e-3; to 5.000e-4, say: a growth of 6.00e-2")
                && !dense.contains("reached")
                && !dense.contains("courant"),
            "{dense}"
        );
        // A growth of 0.104 (a user's soft block at `courant = 0.5`, which halving
        // the step did not hold and a quarter did): the step times 0.04 / 0.104.
        let fixed = energy_growth_hint(
            0.104,
            Some((120, 0.25)),
            Some((120, 0.25, 0.6)),
            400,
            1e-3,
            Some(2e-3),
            false,
            12.0,
            3,
        );
        for part in [
            "the time step `time.dt` = 1.000e-3 is 0.50 of the critical step 2.000e-3",
            "lower `time.dt` (to 3.846e-4, say: a growth of 1.04e-1",
        ] {
            assert!(fixed.contains(part), "`{part}` not in: {fixed}");
        }
        assert!(!fixed.contains("courant"), "{fixed}");
        // The bound crossed early on a small scale; most of the growth came at an
        // impact later: both named. A rise held by a fifth of the growth or less,
        // or in the crossing's step, is not.
        let impact = energy_growth_hint(
            0.08,
            Some((12, 0.03)),
            Some((300, 0.75, 0.45)),
            400,
            1e-3,
            Some(2e-3),
            true,
            12.0,
            3,
        );
        assert!(
            impact.contains("it reached the bound at t = 0.0300 (step 12 of 400) and grew most at t = 0.7500 (step 300: 45 % of the growth in that step)"),
            "{impact}"
        );
        let spread = energy_growth_hint(
            0.08,
            Some((12, 0.03)),
            Some((300, 0.75, 0.1)),
            400,
            1e-3,
            Some(2e-3),
            true,
            12.0,
            3,
        );
        assert!(!spread.contains("grew most"), "{spread}");
        // An instability growing far faster than the step: no less than a quarter.
        let fast = energy_growth_hint(0.9, None, None, 400, 1e-3, Some(2e-3), true, 12.0, 3);
        assert!(
            fast.contains("lower `time.courant` (to 0.12, say"),
            "{fast}"
        );
    }
}
