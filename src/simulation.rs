//! Running a [`Scene`]: build its mesh, basis, particles, effects and driver, step to
//! the end time, and measure the error against the scene's reference solution.
//!
//! The run reports every step through a callback (the CLI prints from it, tests read
//! the same values) and ends with a [`Summary`]. A run that fails numerically (a
//! particle leaves the mesh, the mass matrix is not positive definite, a value is not
//! finite) is not an `Err`: its summary says `stable = false` with the reason and the
//! step, and everything measured up to there, so that instabilities are reported as
//! results. `Err` is for scenes that cannot be set up.
//!
//! "Stable" follows `shared/docs/benchmarks.md`: no failure, the total energy
//! (kinetic + strain + gravitational − work of the non-conservative effects) never
//! exceeds its initial value by more than [`STABLE_ENERGY_GROWTH`] of the energy
//! scale, and every condition estimate (when requested) stays below
//! [`STABLE_CONDITION`].

use crate::bases::BasisKind;
use crate::driver::{Driver, Fix, PhaseTimes, SetupError, StepError, StepReport};
use crate::effect::{BodyForce, Effect, Geostatic, Gravity, InitialStress, LocalDamping, Traction};
use crate::mass::MassStrategy;
use crate::material::{AnyMaterial, Elastic, LinearElastic, NeoHookean};
use crate::particles::Particles;
use crate::scene::{
    BlockLayout, Component, EffectSpec, InitialVelocity, MaterialModel, MeshSpec, Reference, Scene,
};
use crate::studies::exact;
use nalgebra::{SMatrix, SVector};
use psmpm_basis::basis::bspline1d::QuadraticBSpline;
use psmpm_basis::basis::linear::Linear;
use psmpm_basis::basis::linear1d::Linear1d;
use psmpm_basis::basis::powell_sabin::PowellSabin;
use psmpm_basis::mesh::generators::{self, PolygonDomain};
use psmpm_basis::{Basis, Mesh1d, TriMesh, Vec2};
use serde::Serialize;
use std::f64::consts::PI;

/// Energy growth (relative to the energy scale) above which a run is unstable.
pub const STABLE_ENERGY_GROWTH: f64 = 0.05;
/// Condition-number estimate above which a run is unstable.
pub const STABLE_CONDITION: f64 = 1e8;

/// Why a scene could not be run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// Bad parameters or set-up (the message names the field).
    #[error("{0}")]
    Setup(String),
}

impl From<SetupError> for RunError {
    fn from(e: SetupError) -> Self {
        RunError::Setup(e.to_string())
    }
}

impl From<crate::scene::SceneError> for RunError {
    fn from(e: crate::scene::SceneError) -> Self {
        RunError::Setup(e.to_string())
    }
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
    /// eq. (47)), `max-relative-sigma-yy` (paper eq. (48)).
    pub error_measure: Option<&'static str>,
    /// Largest number of lumped rows in a step.
    pub max_lumped_rows: usize,
    /// Largest number of deactivated functions in a step.
    pub max_deactivated: usize,
    /// Most functions the extension expressed through their neighbours in a step.
    pub max_extended: usize,
    /// The critical time step of the basis, mass strategy and material at the start
    /// ([`Driver::critical_time_step`]), when it could be estimated.
    pub dt_critical: Option<f64>,
    /// Largest condition-number estimate (when requested).
    pub max_condition: Option<f64>,
    /// Total energy at the start.
    pub energy_initial: f64,
    /// Total energy at the end.
    pub energy_final: f64,
    /// Largest `|E(t) − E(0)|` relative to the largest energy scale seen.
    pub energy_drift: f64,
    /// Largest `E(t) − E(0)` relative to the energy scale (growth only).
    pub energy_growth: f64,
    /// The verdict of the module doc.
    pub stable: bool,
    /// Why the run stopped early, with the step.
    pub failure: Option<String>,
    /// Wall time of the time loop.
    pub seconds: f64,
    /// Wall time per phase, summed over the steps.
    #[serde(skip)]
    pub phases: PhaseTimes,
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

/// Runs `scene` (1D or 2D), showing every step's report and particles to `observer`.
pub fn observe(scene: &Scene, observer: &mut Observer) -> Result<Summary, RunError> {
    let mut steps_only = |r: &StepReport, p: ParticlesRef<'_>| {
        if r.step > 0 {
            observer(r, p)
        }
    };
    match scene.dim {
        2 => run_2d_observed(scene, &mut steps_only).map(|o| o.summary),
        _ => run_1d_observed(scene, &mut steps_only).map(|o| o.summary),
    }
}

/// Runs a 2D scene, showing `observer` the initial state (a report with `step == 0`)
/// and then every step, and returns its particles and tracked histories.
pub fn observe_2d(scene: &Scene, observer: &mut Observer) -> Result<Outcome<2>, RunError> {
    run_2d_observed(scene, observer)
}

/// Runs a 1D scene, showing `observer` the initial state (a report with `step == 0`)
/// and then every step, and returns its particles and tracked histories.
pub fn observe_1d(scene: &Scene, observer: &mut Observer) -> Result<Outcome<1>, RunError> {
    run_1d_observed(scene, observer)
}

/// The mesh of a 2D scene and its smallest edge length.
pub fn triangulation(scene: &Scene) -> Result<TriMesh, RunError> {
    let mesh = match &scene.mesh {
        MeshSpec::Blocks {
            x,
            y,
            blocks,
            layout,
        } => match layout {
            BlockLayout::FourTriangles => {
                generators::block_grid(x[0], x[1], y[0], y[1], blocks[0], blocks[1])
            }
            BlockLayout::Delaunay => {
                generators::block_delaunay(x[0], x[1], y[0], y[1], blocks[0], blocks[1])
            }
        }
        .map_err(|e| RunError::Setup(format!("mesh: {e}")))?,
        MeshSpec::Polygon {
            outline,
            tags,
            holes,
            edge_length,
        } => {
            let points = |o: &[[f64; 2]]| o.iter().map(|p| Vec2::new(p[0], p[1])).collect();
            let domain = PolygonDomain {
                outer: points(outline),
                outer_tags: if tags.is_empty() {
                    vec!["boundary".to_string(); outline.len()]
                } else {
                    tags.clone()
                },
                holes: holes
                    .iter()
                    .map(|h| (points(&h.outline), h.tag.clone()))
                    .collect(),
            };
            generators::polygon_mesh(&domain, *edge_length).map_err(|e| {
                let e = e.to_string();
                let field = if e.contains("edge_length") {
                    "mesh.edge_length"
                } else {
                    "mesh.outline"
                };
                RunError::Setup(format!("{field}: {e}"))
            })?
        }
        MeshSpec::Gmsh { file } => psmpm_basis::mesh::gmsh::read_msh(std::path::Path::new(file))
            .map_err(|e| RunError::Setup(format!("mesh.file: {e}")))?,
        MeshSpec::Interval { .. } => {
            return Err(RunError::Setup("mesh.kind: `interval` is a 1D mesh".into()))
        }
    };
    Ok(mesh)
}

/// Every boundary condition names a tag of the mesh.
fn check_tags(scene: &Scene, tags: &[String]) -> Result<(), RunError> {
    for (b, bc) in scene.boundaries.iter().enumerate() {
        if !tags.contains(&bc.tag) {
            return Err(RunError::Setup(format!(
                "boundary[{b}].tag: unknown boundary tag `{}`; the mesh has tags {tags:?}",
                bc.tag
            )));
        }
    }
    Ok(())
}

/// The unit normal of every slip wall (`fix = ["normal"]`): the boundary edges with
/// the wall's tag must all be parallel (a straight wall).
fn wall_normals(scene: &Scene, mesh: &TriMesh) -> Result<Vec<(String, [f64; 2])>, RunError> {
    let mut walls = Vec::new();
    for (b, bc) in scene.boundaries.iter().enumerate() {
        if !bc.fix.contains(&Component::Normal) {
            continue;
        }
        let id = mesh
            .tag_id(&bc.tag)
            .map_err(|e| RunError::Setup(format!("boundary[{b}].tag: {e}")))?;
        let mut normal: Option<Vec2> = None;
        for e in mesh.edges().iter().filter(|e| e.tag == Some(id)) {
            let d = mesh.vertices()[e.vertices[1]] - mesh.vertices()[e.vertices[0]];
            let n = Vec2::new(d[1], -d[0]).normalize();
            match normal {
                None => normal = Some(n),
                Some(m) if (m[0] * n[1] - m[1] * n[0]).abs() > 1e-9 => {
                    return Err(RunError::Setup(format!(
                        "boundary[{b}].fix: `normal` needs a straight wall, but `{}` bends",
                        bc.tag
                    )))
                }
                Some(_) => {}
            }
        }
        let n = normal.ok_or_else(|| {
            RunError::Setup(format!(
                "boundary[{b}].tag: `{}` has no boundary edge",
                bc.tag
            ))
        })?;
        walls.push((bc.tag.clone(), [n[0], n[1]]));
    }
    Ok(walls)
}

fn smallest_edge(mesh: &TriMesh) -> f64 {
    mesh.edges()
        .iter()
        .map(|e| (mesh.vertices()[e.vertices[0]] - mesh.vertices()[e.vertices[1]]).norm())
        .fold(f64::INFINITY, f64::min)
}

/// Runs a 2D scene and returns its particles too.
pub fn run_2d(scene: &Scene, on_step: &mut dyn FnMut(&StepReport)) -> Result<Outcome<2>, RunError> {
    run_2d_observed(scene, &mut |r, _| {
        if r.step > 0 {
            on_step(r)
        }
    })
}

/// Runs a 1D scene and returns its particles too.
pub fn run_1d(scene: &Scene, on_step: &mut dyn FnMut(&StepReport)) -> Result<Outcome<1>, RunError> {
    run_1d_observed(scene, &mut |r, _| {
        if r.step > 0 {
            on_step(r)
        }
    })
}

fn run_2d_observed(scene: &Scene, on_step: &mut Observer) -> Result<Outcome<2>, RunError> {
    scene.validate()?;
    if scene.dim != 2 {
        return Err(RunError::Setup(format!("dim: the scene is {}D", scene.dim)));
    }
    let mesh = triangulation(scene)?;
    let h = smallest_edge(&mesh);
    check_tags(scene, mesh.tags())?;
    let walls = wall_normals(scene, &mesh)?;
    match scene.basis {
        BasisKind::Ps => {
            let b = PowellSabin::<f64>::new(mesh, scene.split)
                .map_err(|e| RunError::Setup(format!("basis: {e}")))?;
            dispatch_mass::<2, _>(scene, b, h, &walls, on_step)
        }
        _ => dispatch_mass::<2, _>(scene, Linear::<f64>::new(mesh), h, &walls, on_step),
    }
}

fn run_1d_observed(scene: &Scene, on_step: &mut Observer) -> Result<Outcome<1>, RunError> {
    scene.validate()?;
    let MeshSpec::Interval { x, elements } = scene.mesh else {
        return Err(RunError::Setup(
            "mesh.kind: a 1D scene needs an `interval` mesh".into(),
        ));
    };
    let mesh =
        Mesh1d::uniform(x[0], x[1], elements).map_err(|e| RunError::Setup(format!("mesh: {e}")))?;
    let h = (x[1] - x[0]) / elements as f64;
    // In 1D the normal of a wall is the axis.
    check_tags(scene, &mesh.tags().map(String::from))?;
    let walls: Vec<(String, [f64; 2])> = scene
        .boundaries
        .iter()
        .filter(|bc| bc.fix.contains(&Component::Normal))
        .map(|bc| (bc.tag.clone(), [1.0, 0.0]))
        .collect();
    match scene.basis {
        BasisKind::Bspline => dispatch_mass::<1, _>(
            scene,
            QuadraticBSpline::<f64>::new(mesh),
            h,
            &walls,
            on_step,
        ),
        _ => dispatch_mass::<1, _>(scene, Linear1d::<f64>::new(mesh), h, &walls, on_step),
    }
}

fn dispatch_mass<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    basis: B,
    h: f64,
    walls: &[(String, [f64; 2])],
    on_step: &mut Observer,
) -> Result<Outcome<D>, RunError>
where
    Particles<f64, D>: AsParticlesRef,
{
    run_with::<D, B>(scene, basis, h, walls, on_step)
}

/// Particle positions and volumes of the scene's bodies, block by block for
/// `per_block` layouts (the order of the seeds' codes), row by row otherwise; a
/// body's `jitter` moves each particle inside its cell (deterministic, see
/// [`crate::scene::Body::jitter`]).
pub fn particle_lattice(scene: &Scene) -> Result<Lattice, RunError> {
    let d = scene.dim;
    let mut lattice = Lattice::default();
    for (b, body) in scene.bodies.iter().enumerate() {
        let first = lattice.positions.len();
        let mut spacing = [1.0; 2];
        let mut cells = [1usize; 2];
        let mut group = [1usize; 2];
        for k in 0..d {
            let extent = body.max[k] - body.min[k];
            let h = scene.lattice_spacing(body, k).ok_or_else(|| {
                RunError::Setup(format!("body[{b}].per_block: the mesh has no blocks"))
            })?;
            let n = if let Some(per) = &body.per_block {
                let n = extent / h;
                if (n - n.round()).abs() > 1e-6 * n.max(1.0) || n.round() < 1.0 {
                    return Err(RunError::Setup(format!(
                        "body[{b}].max: the body's extent {extent} along axis {k} is not a whole number of lattice cells of size {h}"
                    )));
                }
                group[k] = per[k];
                n.round() as usize
            } else {
                let c = body.count.as_ref().map_or(1, |c| c[k]);
                group[k] = c;
                c
            };
            spacing[k] = h;
            cells[k] = n;
        }
        let volume: f64 = spacing[..d].iter().product();
        // Jitter: a uniform offset in [-jitter, jitter) cells per axis, drawn in the
        // order the particles are made, from a generator seeded per body.
        let mut rng = psmpm_basis::rng::SplitMix64(
            body.seed
                .unwrap_or(crate::scene::DEFAULT_JITTER_SEED)
                .wrapping_add(b as u64),
        );
        let groups = [cells[0].div_ceil(group[0]), cells[1].div_ceil(group[1])];
        for gj in 0..groups[1] {
            for gi in 0..groups[0] {
                for j in 0..group[1] {
                    for i in 0..group[0] {
                        let (ci, cj) = (gi * group[0] + i, gj * group[1] + j);
                        if ci >= cells[0] || cj >= cells[1] {
                            continue;
                        }
                        let mut p = [0.0; 2];
                        for (k, c) in [ci, cj].into_iter().enumerate().take(d) {
                            let offset = if body.jitter > 0.0 {
                                body.jitter * (2.0 * rng.next_f64() - 1.0)
                            } else {
                                0.0
                            };
                            p[k] = body.min[k] + (c as f64 + 0.5 + offset) * spacing[k];
                        }
                        lattice.positions.push(p);
                        lattice.volumes.push(volume);
                    }
                }
            }
        }
        lattice.body_sizes.push(lattice.positions.len() - first);
    }
    Ok(lattice)
}

/// The particles of a scene's bodies before the run: positions, volumes, and how
/// many belong to each body (bodies in order).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Lattice {
    /// Positions (the second entry is 0 in 1D).
    pub positions: Vec<[f64; 2]>,
    /// Volumes.
    pub volumes: Vec<f64>,
    /// Particles per body.
    pub body_sizes: Vec<usize>,
}

fn to_vec<const D: usize>(p: [f64; 2]) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|k, _| p[k])
}

fn from_vec<const D: usize>(v: &SVector<f64, D>) -> [f64; 2] {
    let mut p = [0.0; 2];
    for k in 0..D {
        p[k] = v[k];
    }
    p
}

/// The scene's reference solution with its parameters resolved.
#[derive(Debug, Clone, Copy)]
enum Solution {
    Bar(exact::VibratingBar),
    Column(exact::ColumnSelfWeight),
    AxisAligned(exact::AxisAligned),
    Equilibrium {
        height: f64,
        density: f64,
        gravity: f64,
        young: f64,
    },
}

impl Solution {
    fn new(scene: &Scene) -> Option<Self> {
        let m = &scene.material;
        let body = &scene.bodies[0];
        let d = scene.dim;
        let gravity = scene.gravity().map_or(0.0, |g| g[d - 1]);
        Some(match scene.reference? {
            Reference::VibratingBar { v0 } => Solution::Bar(exact::VibratingBar {
                length: body.max[0] - body.min[0],
                young: m.young,
                density: m.density,
                v0,
            }),
            Reference::ColumnSelfWeight {} => Solution::Column(exact::ColumnSelfWeight {
                height: body.max[d - 1] - body.min[d - 1],
                young: m.young,
                density: m.density,
                gravity,
            }),
            Reference::AxisAligned { u0 } => Solution::AxisAligned(exact::AxisAligned {
                u0,
                young: m.young,
                poisson: m.poisson,
                density: m.density,
            }),
            Reference::ColumnEquilibrium {} => Solution::Equilibrium {
                height: body.max[d - 1] - body.min[d - 1],
                density: m.density,
                gravity,
                young: m.young,
            },
        })
    }

    /// Exact displacement at reference position `x0` (relative to the body's
    /// lower corner `origin`) and time `t`, in the scene's dimension.
    fn displacement(&self, x0: [f64; 2], origin: [f64; 2], dim: usize, t: f64) -> [f64; 2] {
        match self {
            Solution::Bar(bar) => [bar.displacement(x0[0] - origin[0], t), 0.0],
            Solution::Column(column) => {
                let u = column.displacement(x0[dim - 1] - origin[dim - 1], t);
                if dim == 1 {
                    [u, 0.0]
                } else {
                    [0.0, u]
                }
            }
            Solution::AxisAligned(a) => a.displacement(x0, t),
            Solution::Equilibrium { .. } => [0.0; 2],
        }
    }

    fn velocity(&self, x0: [f64; 2], origin: [f64; 2], dim: usize, t: f64) -> [f64; 2] {
        match self {
            Solution::Bar(bar) => [bar.velocity(x0[0] - origin[0], t), 0.0],
            Solution::AxisAligned(a) => a.velocity(x0, t),
            Solution::Column(column) => {
                let v = column.velocity(x0[dim - 1] - origin[dim - 1], t);
                if dim == 1 {
                    [v, 0.0]
                } else {
                    [0.0, v]
                }
            }
            Solution::Equilibrium { .. } => [0.0; 2],
        }
    }
}

/// The effects `scene` declares, built for `particles` (traction selects its
/// particles here). Only these are assembled in a run.
pub fn build_effects<const D: usize>(
    scene: &Scene,
    particles: &Particles<f64, D>,
) -> Result<Vec<Box<dyn Effect<f64, D>>>, RunError> {
    let solution = Solution::new(scene);
    let mut effects: Vec<Box<dyn Effect<f64, D>>> = Vec::new();
    for (i, spec) in scene.effects.iter().enumerate() {
        match spec {
            EffectSpec::Gravity { g } => effects.push(Box::new(Gravity {
                g: SVector::<f64, D>::from_fn(|k, _| g[k]),
            })),
            EffectSpec::Damping { alpha } => effects.push(Box::new(LocalDamping { alpha: *alpha })),
            EffectSpec::Traction {
                min,
                max,
                traction,
                length,
                ramp,
            } => {
                let selected: Vec<usize> = (0..particles.len())
                    .filter(|&p| (0..D).all(|k| (min[k]..=max[k]).contains(&particles.x0[p][k])))
                    .collect();
                if selected.is_empty() {
                    return Err(RunError::Setup(format!(
                        "effect[{i}].min: the traction box selects no particle"
                    )));
                }
                let share = length / selected.len() as f64;
                effects.push(Box::new(Traction {
                    particles: selected,
                    force: SVector::<f64, D>::from_fn(|k, _| traction[k] * share),
                    ramp: *ramp,
                }));
            }
            EffectSpec::BodyForce { value } => {
                let b = SVector::<f64, D>::from_fn(|k, _| value[k]);
                effects.push(Box::new(BodyForce {
                    label: "body-force",
                    field: Box::new(move |_, _| b),
                }));
            }
            EffectSpec::ManufacturedBodyForce {} => {
                let Some(Solution::AxisAligned(a)) = solution else {
                    return Err(RunError::Setup(format!(
                        "effect[{i}].kind: `manufactured-body-force` needs reference kind `axis-aligned`"
                    )));
                };
                effects.push(Box::new(BodyForce {
                    label: "manufactured-body-force",
                    field: Box::new(move |x0: &SVector<f64, D>, t| {
                        to_vec::<D>(a.body_force(from_vec(x0), t))
                    }),
                }));
            }
            EffectSpec::GeostaticStress { .. } => {} // set up on the particles
        }
    }
    Ok(effects)
}

fn run_with<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    basis: B,
    h: f64,
    walls: &[(String, [f64; 2])],
    on_step: &mut Observer,
) -> Result<Outcome<D>, RunError>
where
    Particles<f64, D>: AsParticlesRef,
{
    let m = &scene.material;
    let elastic = Elastic::new(m.young, m.poisson, m.density)
        .map_err(|e| RunError::Setup(format!("material: {e}")))?;
    let material = match m.model {
        MaterialModel::LinearElastic => AnyMaterial::Linear(LinearElastic::new(elastic, D)),
        MaterialModel::NeoHookean => AnyMaterial::NeoHookean(NeoHookean::new(elastic, D)),
    };
    let solution = Solution::new(scene);
    let origin = {
        let mut o = [0.0; 2];
        o[..D].copy_from_slice(&scene.bodies[0].min[..D]);
        o
    };
    let Lattice {
        positions,
        volumes,
        body_sizes,
    } = particle_lattice(scene)?;
    let mut particles = Particles::<f64, D>::new(
        positions.iter().map(|&p| to_vec::<D>(p)).collect(),
        volumes,
        elastic.density,
    );
    for (p, &x0) in positions.iter().enumerate() {
        let v = match &scene.initial_velocity {
            InitialVelocity::Rest {} => [0.0; 2],
            InitialVelocity::Uniform { value } => {
                let mut v = [0.0; 2];
                v[..D].copy_from_slice(&value[..D]);
                v
            }
            InitialVelocity::SineMode { v0 } => {
                let body = &scene.bodies[0];
                let length = body.max[0] - body.min[0];
                [v0 * (PI * (x0[0] - body.min[0]) / length).sin(), 0.0]
            }
            InitialVelocity::Exact {} => {
                solution.map_or([0.0; 2], |s| s.velocity(x0, origin, D, 0.0))
            }
        };
        particles.v[p] = to_vec::<D>(v);
    }
    for spec in &scene.effects {
        if let EffectSpec::GeostaticStress { surface, k0 } = spec {
            let g = scene.gravity().map_or(0.0, |g| g[D - 1]);
            let state = Geostatic {
                surface: *surface,
                density: elastic.density,
                gravity: g,
                k0: *k0,
            };
            for p in 0..particles.len() {
                let s: SMatrix<f64, D, D> = state.sigma0(&particles.x0[p]);
                particles.sigma0[p] += s;
            }
        }
    }
    let effects = build_effects(scene, &particles)?;
    let fixes: Vec<Fix> = scene
        .boundaries
        .iter()
        .flat_map(|bc| {
            bc.fix.iter().filter_map(|c| {
                c.axis().map(|component| Fix {
                    tag: bc.tag.clone(),
                    component,
                })
            })
        })
        .collect();
    // With `courant` the step is fixed below, from the critical step; this one
    // (a mesh-based guess) only sets the driver up.
    let mut dt = scene.dt(h);
    if !(dt > 0.0 && dt.is_finite()) {
        return Err(RunError::Setup(format!(
            "time: the time step {dt} is not positive"
        )));
    }
    let functions = basis.num_functions();
    let mut driver: Driver<f64, D, B, Box<dyn MassStrategy<f64>>, AnyMaterial> =
        Driver::new(
            basis,
            particles,
            material,
            scene.mass.build::<f64>(),
            &fixes,
            effects,
            dt,
        ).map_err(
            |e| match e {
                SetupError::ParticleOutside { particle, position } => {
                    // Name the body the particle belongs to.
                    let mut first = 0;
                    let body = body_sizes
                        .iter()
                        .position(|&n| {
                            first += n;
                            particle < first
                        })
                        .unwrap_or(0);
                    RunError::Setup(format!(
                        "body[{body}].max: the particle at {position:?} lies outside the mesh; the body's box must lie inside the meshed domain"
                    ))
                }
                other => other.into(),
            },
        )?;
    driver.estimate_condition = scene.output.condition;
    for (tag, normal) in walls {
        let n = SVector::<f64, D>::from_fn(|k, _| normal[k]);
        driver.add_slip_wall(tag, &n)?;
    }

    // The critical step at the start (a failure here is the failure of step 1,
    // reported by the first step itself).
    let dt_critical = driver.critical_time_step().ok().filter(|c| c.is_finite());
    let steps = match scene.time.courant {
        // Courant number of the critical step, rounded so that the run ends at t_end.
        Some(c) => {
            let steps = (scene.time.t_end / (c * dt_critical.unwrap_or(dt / c)))
                .ceil()
                .max(1.0) as usize;
            dt = scene.time.t_end / steps as f64;
            driver.set_dt(dt);
            steps
        }
        None => (scene.time.t_end / dt).round().max(1.0) as usize,
    };

    let mut tracked: Vec<Tracked> = scene
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
                x0: positions[particle],
                time: Vec::with_capacity(steps),
                velocity: Vec::with_capacity(steps),
                displacement: Vec::with_capacity(steps),
                exact_displacement: Vec::with_capacity(if solution.is_some() { steps } else { 0 }),
            }
        })
        .collect();

    let start = driver.report();
    // The initial state (step 0); the public entry points other than
    // `observe_2d`/`observe_1d` pass only steps > 0 on.
    on_step(&start, driver.particles.view());
    let e0 = start.total_energy();
    let mut scale = e0
        .abs()
        .max(start.kinetic)
        .max(start.strain)
        .max(start.potential.abs());
    let (mut drift, mut growth) = (0.0f64, 0.0f64);
    let (mut lumped, mut deactivated, mut extended) = (0usize, 0usize, 0usize);
    let mut max_condition: Option<f64> = None;
    let mut phases = PhaseTimes::default();
    let mut rms = exact::RmsPositionError::default();
    let mut failure = None;
    let clock = std::time::Instant::now();
    for _ in 0..steps {
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
            if let Some(s) = solution {
                t.exact_displacement
                    .push(s.displacement(t.x0, origin, D, r.time));
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
        on_step(&r, driver.particles.view());
        scale = scale.max(r.kinetic).max(r.strain).max(r.potential.abs());
        drift = drift.max((r.total_energy() - e0).abs());
        growth = growth.max(r.total_energy() - e0);
        lumped = lumped.max(r.mass_report.lumped_rows);
        deactivated = deactivated.max(r.mass_report.deactivated);
        extended = extended.max(r.mass_report.extended);
        phases.evaluate += r.phases.evaluate;
        phases.assemble += r.phases.assemble;
        phases.solve += r.phases.solve;
        phases.update += r.phases.update;
        if let Some(c) = r.condition {
            max_condition = Some(max_condition.map_or(c, |m: f64| m.max(c)));
        }
    }
    let seconds = clock.elapsed().as_secs_f64();
    let end = driver.report();
    let parts = &driver.particles;
    let error = solution.and_then(|s| match s {
        // Paper eq. (47) needs at least one step.
        Solution::AxisAligned(_) => (rms.steps() > 0).then(|| rms.value()),
        Solution::Equilibrium {
            height,
            density,
            gravity,
            young,
        } => {
            let sigma_base = (height * density * gravity).abs();
            let worst = (0..parts.len())
                .map(|p| {
                    let y = parts.x[p][D - 1] - origin[D - 1];
                    let exact = exact::column_equilibrium_stress_linear(
                        y,
                        height,
                        density,
                        gravity.abs(),
                        young,
                    );
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
    });
    let scale = scale.max(f64::MIN_POSITIVE);
    let (energy_drift, energy_growth) = (drift / scale, growth / scale);
    let stable = failure.is_none()
        && energy_growth < STABLE_ENERGY_GROWTH
        && max_condition.is_none_or(|c| c < STABLE_CONDITION);
    Ok(Outcome {
        summary: Summary {
            scene: scene.name.clone(),
            basis: scene.basis.name(),
            mass: scene.mass.spec(),
            functions,
            particles: parts.len(),
            steps: driver.steps(),
            dt,
            t_end: driver.time(),
            error,
            error_measure: scene.reference.map(|r| r.error_measure()),
            max_lumped_rows: lumped,
            max_deactivated: deactivated,
            max_extended: extended,
            dt_critical,
            max_condition,
            energy_initial: e0,
            energy_final: end.total_energy(),
            energy_drift,
            energy_growth,
            stable,
            failure: failure.as_ref().map(|e| e.to_string()),
            seconds,
            phases,
        },
        particles: driver.particles,
        tracked,
        failure,
    })
}
