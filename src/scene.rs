//! Built-in scenes: the seeds' benchmarks as runnable, parameterised set-ups with
//! their exact solutions (`shared/docs/benchmarks.md`).
//!
//! | name | benchmark | dim | physics |
//! |---|---|---|---|
//! | `vibrating-bar` | B2 (thesis §4.1) | 2 | elasticity |
//! | `column-small` | B5a (thesis §4.3) | 2 | elasticity, gravity |
//! | `vibrating-bar-1d` | B2 in 1D | 1 | elasticity |
//! | `column-small-1d` | B5a in 1D | 1 | elasticity, gravity |
//!
//! A scene declares its physics: only the effects it lists are assembled (the bar
//! has no gravity, so gravity is never evaluated for it).

use crate::bases::BasisKind;
use crate::driver::{Driver, Fix, PhaseTimes, SetupError, StepError, StepReport};
use crate::effect::{Effect, Gravity};
pub use crate::mass::MassKind;
use crate::mass::{Lumped, MassStrategy, SparseMass};
use crate::material::{Elastic, LinearElastic};
use crate::particles::Particles;
use crate::sparse::Scalar;
use nalgebra::SVector;
use psmpm_basis::basis::bspline1d::QuadraticBSpline;
use psmpm_basis::basis::linear::Linear;
use psmpm_basis::basis::linear1d::Linear1d;
use psmpm_basis::basis::powell_sabin::{PowellSabin, SplitPoint};
use psmpm_basis::mesh::generators;
use psmpm_basis::{Basis, Mesh1d, TriMesh};
use serde::Serialize;
use std::f64::consts::PI;

/// Which benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Benchmark {
    /// B2: small-deformation vibrating bar.
    VibratingBar,
    /// B5a: small-deformation column under self-weight.
    ColumnSmall,
}

/// How the rectangle is triangulated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grid {
    /// Four triangles per block around a centre vertex (the seeds' grid).
    Blocks,
    /// Delaunay triangulation of block corners and centres (the thesis' tables).
    BlockDelaunay,
}

/// A fully specified run of a built-in scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Scene name.
    pub name: &'static str,
    /// Benchmark.
    pub benchmark: Benchmark,
    /// 1 or 2.
    pub dim: usize,
    /// Basis.
    pub basis: BasisKind,
    /// Mass strategy.
    pub mass: MassKind,
    /// Blocks `(n_x, n_y)` (1D: elements, 1).
    pub blocks: (usize, usize),
    /// Particles per block `(p_x, p_y)` (1D: per element, 1).
    pub particles_per_block: (usize, usize),
    /// Time step.
    pub dt: f64,
    /// End time.
    pub t_end: f64,
    /// Initial velocity amplitude (vibrating bar).
    pub v0: f64,
    /// PS split points.
    pub split: SplitPoint,
    /// Triangulation of the rectangle.
    pub grid: Grid,
    /// Estimate the mass-matrix condition number every step (costs ~60 solves).
    pub condition: bool,
    /// Points whose nearest particles are tracked (velocity and displacement every step).
    pub tracked: Vec<[f64; 2]>,
}

/// Names of the built-in scenes, with one line each.
pub const BUILTIN: [(&str, &str); 4] = [
    (
        "vibrating-bar",
        "B2: elastic bar L = 25, H = 2 vibrating in its first mode (v0 = 0.1)",
    ),
    (
        "column-small",
        "B5a: elastic column H = 25, W = 2 settling under self-weight",
    ),
    ("vibrating-bar-1d", "B2 in 1D (quadratic B-spline or 1D PL)"),
    ("column-small-1d", "B5a in 1D (quadratic B-spline or 1D PL)"),
];

/// Bar length, height, material (B2).
const BAR: (f64, f64, f64, f64) = (25.0, 2.0, 1.0, 100.0);
/// Column height, width, density, Young's modulus, gravity (B5a).
const COLUMN: (f64, f64, f64, f64, f64) = (25.0, 2.0, 1.0, 5e4, -9.81);

impl Scene {
    /// The built-in scene `name` with its default basis and resolution. The error
    /// lists the known scenes.
    pub fn builtin(name: &str) -> Result<Self, String> {
        let scene = match name {
            "vibrating-bar" => Scene {
                name: "vibrating-bar",
                benchmark: Benchmark::VibratingBar,
                dim: 2,
                basis: BasisKind::Ps,
                mass: MassKind::Consistent,
                blocks: (4, 1),
                particles_per_block: (24, 6),
                dt: 1e-3,
                t_end: 5.0,
                v0: 0.1,
                split: SplitPoint::Incentre,
                grid: Grid::Blocks,
                condition: false,
                tracked: Vec::new(),
            },
            "column-small" => Scene {
                name: "column-small",
                benchmark: Benchmark::ColumnSmall,
                dim: 2,
                basis: BasisKind::Ps,
                mass: MassKind::Consistent,
                blocks: (1, 8),
                particles_per_block: (6, 8),
                dt: 1e-4,
                t_end: 1.0,
                v0: 0.0,
                split: SplitPoint::Incentre,
                grid: Grid::Blocks,
                condition: false,
                tracked: Vec::new(),
            },
            "vibrating-bar-1d" => Scene {
                name: "vibrating-bar-1d",
                dim: 1,
                basis: BasisKind::Bspline,
                blocks: (8, 1),
                particles_per_block: (4, 1),
                ..Self::builtin("vibrating-bar")?
            },
            "column-small-1d" => Scene {
                name: "column-small-1d",
                dim: 1,
                basis: BasisKind::Bspline,
                blocks: (8, 1),
                particles_per_block: (4, 1),
                ..Self::builtin("column-small")?
            },
            _ => {
                let known: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
                return Err(format!(
                    "unknown scene `{name}` (known: {})",
                    known.join(", ")
                ));
            }
        };
        Ok(scene)
    }

    /// The effects the scene declares: gravity for the column, none for the bar.
    /// Only these are assembled.
    pub fn effects<const D: usize>(&self) -> Vec<Box<dyn Effect<f64, D>>> {
        let mut effects: Vec<Box<dyn Effect<f64, D>>> = Vec::new();
        if self.benchmark == Benchmark::ColumnSmall {
            let mut g = SVector::<f64, D>::zeros();
            g[D - 1] = COLUMN.4;
            effects.push(Box::new(Gravity { g }));
        }
        effects
    }

    /// Checks that the parameters make a valid run.
    pub fn validate(&self) -> Result<(), String> {
        if self.basis.dim() != self.dim {
            return Err(format!(
                "basis `{}` is {}D but scene `{}` is {}D",
                self.basis.name(),
                self.basis.dim(),
                self.name,
                self.dim
            ));
        }
        if !(self.dt > 0.0 && self.dt.is_finite()) {
            return Err(format!("dt must be positive, got {}", self.dt));
        }
        if !(self.t_end > 0.0 && self.t_end.is_finite()) {
            return Err(format!("t_end must be positive, got {}", self.t_end));
        }
        let (nx, ny) = self.blocks;
        if nx == 0 || ny == 0 || nx > 4096 || ny > 4096 {
            return Err(format!(
                "blocks must be between 1 and 4096 each, got {nx}x{ny}"
            ));
        }
        let (px, py) = self.particles_per_block;
        if px == 0 || py == 0 || px * py > 10_000 {
            return Err(format!(
                "particles per block must be positive (at most 10000), got {px}x{py}"
            ));
        }
        Ok(())
    }

    /// Number of steps to reach `t_end` (rounded to the nearest integer).
    pub fn steps(&self) -> usize {
        (self.t_end / self.dt).round() as usize
    }

    /// Physical extent `(length along the first axis, along the second)`.
    fn extent(&self) -> (f64, f64) {
        match self.benchmark {
            Benchmark::VibratingBar => (BAR.0, BAR.1),
            Benchmark::ColumnSmall => (COLUMN.1, COLUMN.0),
        }
    }

    /// The elastic constants.
    pub fn elastic(&self) -> Elastic {
        match self.benchmark {
            Benchmark::VibratingBar => Elastic::new(BAR.3, 0.0, BAR.2).expect("valid constants"),
            Benchmark::ColumnSmall => {
                Elastic::new(COLUMN.3, 0.0, COLUMN.2).expect("valid constants")
            }
        }
    }

    /// Exact displacement at initial position `x0` (2D coordinates; in 1D only the
    /// first is used and it runs along the bar or up the column) at time `t`.
    pub fn exact_displacement(&self, x0: [f64; 2], t: f64) -> [f64; 2] {
        match self.benchmark {
            Benchmark::VibratingBar => {
                // Thesis eq. (4.2): u_x = (v0/ω) sin(ωt) sin(πx/L), ω = π √(E/ρ) / L.
                let (l, _, rho, e) = BAR;
                let omega = PI * (e / rho).sqrt() / l;
                [
                    self.v0 / omega * (omega * t).sin() * (PI * x0[0] / l).sin(),
                    0.0,
                ]
            }
            Benchmark::ColumnSmall => {
                // Thesis eq. (4.6) with its two sign errors corrected
                // (`shared/docs/benchmarks.md`, B5a).
                let (h, _, rho, e, g) = COLUMN;
                let y = if self.dim == 1 { x0[0] } else { x0[1] };
                let c = (e / rho).sqrt();
                let mut u = rho * g / e * (h * y - 0.5 * y * y);
                for n in 1..=400 {
                    let m = (2 * n - 1) as f64;
                    let k = m * PI / (2.0 * h);
                    let un = 16.0 * rho * g * h * h / (m * m * m * PI.powi(3) * e);
                    u -= un * (c * k * t).cos() * (k * y).sin();
                }
                if self.dim == 1 {
                    [u, 0.0]
                } else {
                    [0.0, u]
                }
            }
        }
    }

    /// Initial velocity at `x0`.
    fn initial_velocity(&self, x0: [f64; 2]) -> [f64; 2] {
        match self.benchmark {
            Benchmark::VibratingBar => [self.v0 * (PI * x0[0] / BAR.0).sin(), 0.0],
            Benchmark::ColumnSmall => [0.0, 0.0],
        }
    }

    /// Particle positions and volumes on the regular lattice of each block (cell centres).
    fn lattice(&self) -> (Vec<[f64; 2]>, Vec<f64>) {
        let (lx, ly) = self.extent();
        let (nx, ny) = if self.dim == 1 {
            (self.blocks.0, 1)
        } else {
            self.blocks
        };
        let (px, py) = if self.dim == 1 {
            (self.particles_per_block.0, 1)
        } else {
            self.particles_per_block
        };
        let along = if self.dim == 1 && self.benchmark == Benchmark::ColumnSmall {
            ly
        } else {
            lx
        };
        let (bx, by) = if self.dim == 1 {
            (along / nx as f64, 1.0)
        } else {
            (lx / nx as f64, ly / ny as f64)
        };
        let volume = if self.dim == 1 {
            bx / px as f64
        } else {
            bx * by / (px * py) as f64
        };
        let mut positions = Vec::new();
        for j in 0..ny {
            for i in 0..nx {
                for b in 0..py {
                    for a in 0..px {
                        positions.push([
                            (i as f64 + (a as f64 + 0.5) / px as f64) * bx,
                            (j as f64 + (b as f64 + 0.5) / py as f64) * by,
                        ]);
                    }
                }
            }
        }
        let n = positions.len();
        (positions, vec![volume; n])
    }

    fn triangulation(&self) -> Result<TriMesh, RunError> {
        let (lx, ly) = self.extent();
        let (nx, ny) = self.blocks;
        let mesh = match self.grid {
            Grid::Blocks => generators::block_grid(0.0, lx, 0.0, ly, nx, ny),
            Grid::BlockDelaunay => generators::block_delaunay(0.0, lx, 0.0, ly, nx, ny),
        };
        mesh.map_err(|e| RunError::Setup(e.to_string()))
    }

    fn fixes(&self) -> Vec<Fix> {
        let fix = |tag: &str, component: usize| Fix {
            tag: tag.into(),
            component,
        };
        match (self.benchmark, self.dim) {
            (Benchmark::VibratingBar, 2) => vec![
                fix("left", 0),
                fix("left", 1),
                fix("right", 0),
                fix("right", 1),
                fix("bottom", 1),
                fix("top", 1),
            ],
            (Benchmark::ColumnSmall, 2) => vec![
                fix("bottom", 0),
                fix("bottom", 1),
                fix("left", 0),
                fix("right", 0),
            ],
            (Benchmark::VibratingBar, _) => vec![fix("left", 0), fix("right", 0)],
            (Benchmark::ColumnSmall, _) => vec![fix("left", 0)],
        }
    }
}

/// Why a run failed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RunError {
    /// Bad parameters or set-up.
    #[error("{0}")]
    Setup(String),
    /// A step failed numerically.
    #[error(transparent)]
    Step(#[from] StepError),
}

impl From<SetupError> for RunError {
    fn from(e: SetupError) -> Self {
        RunError::Setup(e.to_string())
    }
}

/// What a run produced.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Summary {
    /// Scene name.
    pub scene: &'static str,
    /// Basis name.
    pub basis: &'static str,
    /// Mass strategy.
    pub mass: &'static str,
    /// Basis functions.
    pub functions: usize,
    /// Particles.
    pub particles: usize,
    /// Steps taken.
    pub steps: usize,
    /// End time reached.
    pub t_end: f64,
    /// `E_u = sqrt(Σ_p V_p |û_p − u(x_p⁰, t)|²)` at the end (thesis eq. (4.4)).
    pub error: Option<f64>,
    /// Largest number of lumped rows in a step.
    pub max_lumped_rows: usize,
    /// Largest condition-number estimate (when requested).
    pub max_condition: Option<f64>,
    /// Total energy at the start.
    pub energy_initial: f64,
    /// Total energy at the end.
    pub energy_final: f64,
    /// Largest `|E(t) − E(0)|` relative to the largest energy scale seen.
    pub energy_drift: f64,
    /// No failure and energy drift below [`STABLE_ENERGY_DRIFT`].
    pub stable: bool,
    /// Wall time of the time loop.
    pub seconds: f64,
    /// Wall time per phase, summed over the steps.
    #[serde(skip)]
    pub phases: PhaseTimes,
}

/// Energy drift above which a completed run is called unstable.
pub const STABLE_ENERGY_DRIFT: f64 = 0.05;

/// A run's particles and driver state at the end, for tests and output.
pub struct Outcome<T: Scalar, const D: usize> {
    /// Summary.
    pub summary: Summary,
    /// Particles at the end.
    pub particles: Particles<T, D>,
    /// For each tracked point: the particle index and its `(time, velocity,
    /// displacement)` after every step.
    pub tracked: Vec<Tracked>,
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
}

fn to_vec<const D: usize>(p: [f64; 2]) -> SVector<f64, D> {
    SVector::<f64, D>::from_fn(|k, _| p[k])
}

/// Runs `scene` in 2D or 1D as its dimension says, calling `on_step` after every step.
pub fn run(scene: &Scene, on_step: &mut dyn FnMut(&StepReport)) -> Result<Summary, RunError> {
    scene.validate().map_err(RunError::Setup)?;
    match scene.dim {
        2 => run_2d(scene, on_step).map(|o| o.summary),
        _ => run_1d(scene, on_step).map(|o| o.summary),
    }
}

/// Runs a 2D scene and returns its particles too.
pub fn run_2d(
    scene: &Scene,
    on_step: &mut dyn FnMut(&StepReport),
) -> Result<Outcome<f64, 2>, RunError> {
    scene.validate().map_err(RunError::Setup)?;
    let mesh = scene.triangulation()?;
    match scene.basis {
        BasisKind::Ps => {
            let b = PowellSabin::<f64>::new(mesh, scene.split)
                .map_err(|e| RunError::Setup(e.to_string()))?;
            dispatch_mass::<2, _>(scene, b, on_step)
        }
        _ => dispatch_mass::<2, _>(scene, Linear::<f64>::new(mesh), on_step),
    }
}

/// Runs a 1D scene and returns its particles too.
pub fn run_1d(
    scene: &Scene,
    on_step: &mut dyn FnMut(&StepReport),
) -> Result<Outcome<f64, 1>, RunError> {
    scene.validate().map_err(RunError::Setup)?;
    let length = match scene.benchmark {
        Benchmark::VibratingBar => BAR.0,
        Benchmark::ColumnSmall => COLUMN.0,
    };
    let mesh =
        Mesh1d::uniform(0.0, length, scene.blocks.0).map_err(|e| RunError::Setup(e.to_string()))?;
    match scene.basis {
        BasisKind::Bspline => {
            dispatch_mass::<1, _>(scene, QuadraticBSpline::<f64>::new(mesh), on_step)
        }
        _ => dispatch_mass::<1, _>(scene, Linear1d::<f64>::new(mesh), on_step),
    }
}

fn dispatch_mass<const D: usize, B: Basis<f64, D>>(
    scene: &Scene,
    basis: B,
    on_step: &mut dyn FnMut(&StepReport),
) -> Result<Outcome<f64, D>, RunError> {
    match scene.mass {
        MassKind::Lumped => run_with::<D, B, Lumped<f64>>(scene, basis, on_step),
        _ => run_with::<D, B, SparseMass<f64>>(scene, basis, on_step),
    }
}

fn run_with<const D: usize, B: Basis<f64, D>, M: MassStrategy<f64>>(
    scene: &Scene,
    basis: B,
    on_step: &mut dyn FnMut(&StepReport),
) -> Result<Outcome<f64, D>, RunError> {
    let elastic = scene.elastic();
    let (positions, volumes) = scene.lattice();
    let mut particles = Particles::<f64, D>::new(
        positions.iter().map(|&p| to_vec::<D>(p)).collect(),
        volumes,
        elastic.density,
    );
    for (p, x0) in positions.iter().enumerate() {
        particles.v[p] = to_vec::<D>(scene.initial_velocity(*x0));
    }
    let effects = scene.effects::<D>();
    let functions = basis.num_functions();
    let mut driver: Driver<f64, D, B, M, LinearElastic> = Driver::new(
        basis,
        particles,
        LinearElastic::new(elastic, D),
        scene.mass,
        &scene.fixes(),
        effects,
        scene.dt,
    )?;
    driver.estimate_condition = scene.condition;
    let start = driver.report();
    let e0 = start.total_energy();
    let mut max_condition: Option<f64> = None;
    let mut phases = PhaseTimes::default();
    let (mut scale, mut drift, mut lumped) = (
        e0.abs()
            .max(start.kinetic)
            .max(start.strain)
            .max(start.potential.abs()),
        0.0f64,
        0usize,
    );
    let mut tracked: Vec<Tracked> = scene
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
                ..Tracked::default()
            }
        })
        .collect();
    for t in &mut tracked {
        t.time.reserve(scene.steps());
        t.velocity.reserve(scene.steps());
        t.displacement.reserve(scene.steps());
    }
    let clock = std::time::Instant::now();
    for _ in 0..scene.steps() {
        let r = driver.step()?;
        for t in &mut tracked {
            let (v, u) = (
                &driver.particles.v[t.particle],
                &driver.particles.u[t.particle],
            );
            let mut pair = ([0.0; 2], [0.0; 2]);
            for k in 0..D {
                pair.0[k] = v[k];
                pair.1[k] = u[k];
            }
            t.time.push(r.time);
            t.velocity.push(pair.0);
            t.displacement.push(pair.1);
        }
        on_step(&r);
        scale = scale.max(r.kinetic).max(r.strain).max(r.potential.abs());
        drift = drift.max((r.total_energy() - e0).abs());
        lumped = lumped.max(r.mass_report.lumped_rows);
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
    let mut err2 = 0.0;
    for p in 0..parts.len() {
        let mut x0 = [0.0; 2];
        for k in 0..D {
            x0[k] = parts.x0[p][k];
        }
        let exact = scene.exact_displacement(x0, driver.time());
        let mut d2 = 0.0;
        for k in 0..D {
            d2 += (parts.u[p][k] - exact[k]).powi(2);
        }
        err2 += parts.volume[p] * d2;
    }
    let energy_drift = drift / scale.max(f64::MIN_POSITIVE);
    Ok(Outcome {
        summary: Summary {
            scene: scene.name,
            basis: scene.basis.name(),
            mass: scene.mass.name(),
            functions,
            particles: parts.len(),
            steps: driver.steps(),
            t_end: driver.time(),
            error: Some(err2.sqrt()),
            max_lumped_rows: lumped,
            max_condition,
            energy_initial: e0,
            energy_final: end.total_energy(),
            energy_drift,
            stable: energy_drift < STABLE_ENERGY_DRIFT,
            seconds,
            phases,
        },
        particles: driver.particles,
        tracked,
    })
}

/// A scene file: a built-in scene and the parameters it changes, in TOML.
///
/// ```toml
/// scene = "column-small"      # the built-in scene to start from
/// basis = "ps"                # ps, pl (2D); bspline, pl1d (1D)
/// mass = "partial"            # consistent, lumped, partial[:TAU], deactivate[:M]
/// blocks = [2, 16]
/// particles = [6, 8]          # per block
/// dt = 1e-4
/// t_end = 0.5
/// split = "incentre"          # or "centroid"
/// grid = "blocks"             # or "block-delaunay"
/// condition = true
/// tracked = [[1.0, 12.5]]
/// ```
///
/// Unknown keys are rejected; every error names the file, line and column.
#[derive(Debug, Clone, PartialEq, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Built-in scene to start from.
    pub scene: String,
    /// Basis name.
    pub basis: Option<String>,
    /// Mass strategy.
    pub mass: Option<String>,
    /// Blocks `[n_x, n_y]`.
    pub blocks: Option<[usize; 2]>,
    /// Particles per block `[p_x, p_y]`.
    pub particles: Option<[usize; 2]>,
    /// Time step.
    pub dt: Option<f64>,
    /// End time.
    pub t_end: Option<f64>,
    /// Initial velocity amplitude (vibrating bar).
    pub v0: Option<f64>,
    /// `incentre` or `centroid`.
    pub split: Option<String>,
    /// `blocks` or `block-delaunay`.
    pub grid: Option<String>,
    /// Condition estimate every step.
    pub condition: Option<bool>,
    /// Tracked points.
    pub tracked: Option<Vec<[f64; 2]>>,
}

/// An error in a scene file, located.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}:{line}:{column}: {message}")]
pub struct SceneFileError {
    /// File name.
    pub file: String,
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
    /// What is wrong.
    pub message: String,
}

/// 1-based line and column of byte offset `at` in `text`.
fn line_column(text: &str, at: usize) -> (usize, usize) {
    let before = &text[..at.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before
        .rfind('\n')
        .map_or(before.len(), |i| before.len() - i - 1)
        + 1;
    (line, column)
}

impl Scene {
    /// Parses a scene file (`file` names it in errors).
    pub fn from_toml(text: &str, file: &str) -> Result<Self, SceneFileError> {
        let error = |at: usize, message: String| {
            let (line, column) = line_column(text, at);
            SceneFileError {
                file: file.to_string(),
                line,
                column,
                message,
            }
        };
        let parsed: SceneFile = toml::from_str(text).map_err(|e| {
            let at = e.span().map_or(0, |s| s.start);
            error(at, e.message().trim().to_string())
        })?;
        // Locate a key's value for value errors.
        let key_at = |key: &str| -> usize {
            text.lines()
                .scan(0usize, |offset, l| {
                    let start = *offset;
                    *offset += l.len() + 1;
                    Some((start, l))
                })
                .find(|(_, l)| {
                    l.trim_start().starts_with(key)
                        && l.trim_start()[key.len()..].trim_start().starts_with('=')
                })
                .map_or(0, |(start, l)| {
                    start
                        + l.find('=').map_or(0, |i| {
                            i + 1 + (l[i + 1..].len() - l[i + 1..].trim_start().len())
                        })
                })
        };
        let mut s = Scene::builtin(&parsed.scene)
            .map_err(|m| error(key_at("scene"), format!("scene: {m}")))?;
        if let Some(b) = &parsed.basis {
            s.basis =
                BasisKind::parse(b).map_err(|m| error(key_at("basis"), format!("basis: {m}")))?;
        } else if s.dim == 1 {
            s.basis = BasisKind::Bspline;
        }
        if let Some(m) = &parsed.mass {
            s.mass = MassKind::parse(m).map_err(|m| error(key_at("mass"), format!("mass: {m}")))?;
        }
        if let Some([a, b]) = parsed.blocks {
            s.blocks = (a, b);
        }
        if let Some([a, b]) = parsed.particles {
            s.particles_per_block = (a, b);
        }
        if let Some(v) = parsed.dt {
            s.dt = v;
        }
        if let Some(v) = parsed.t_end {
            s.t_end = v;
        }
        if let Some(v) = parsed.v0 {
            if !v.is_finite() {
                return Err(error(key_at("v0"), format!("v0: must be finite, got {v}")));
            }
            s.v0 = v;
        }
        if let Some(v) = &parsed.split {
            s.split = match v.as_str() {
                "incentre" => SplitPoint::Incentre,
                "centroid" => SplitPoint::Centroid,
                other => {
                    return Err(error(
                        key_at("split"),
                        format!("split: unknown split point `{other}` (known: incentre, centroid)"),
                    ))
                }
            };
        }
        if let Some(v) = &parsed.grid {
            s.grid = match v.as_str() {
                "blocks" => Grid::Blocks,
                "block-delaunay" => Grid::BlockDelaunay,
                other => {
                    return Err(error(
                        key_at("grid"),
                        format!("grid: unknown grid `{other}` (known: blocks, block-delaunay)"),
                    ))
                }
            };
        }
        if let Some(c) = parsed.condition {
            s.condition = c;
        }
        if let Some(t) = parsed.tracked {
            s.tracked = t;
        }
        s.validate().map_err(|m| {
            let key = ["dt", "t_end", "particles", "blocks", "basis"]
                .into_iter()
                .find(|k| m.contains(k.trim_end_matches('s')))
                .unwrap_or("scene");
            error(key_at(key), m)
        })?;
        Ok(s)
    }
}
