//! `mpm-cli stability`: the stability matrix. Every case (a scene file in
//! `scenes/stability/`) runs with every mass strategy, and one table says per cell
//! whether the run was stable (and if not, why and at which step), its error against
//! the case's reference, the σ_yy roughness of the column cases, the largest
//! condition estimate of the mass systems, how many functions the strategy treated
//! (lumped rows, deactivated functions) and the wall time per step.
//!
//! A cell is `mpm-cli run scenes/stability/CASE.toml --mass STRATEGY`: the runner
//! changes nothing in a case but its mass strategy. Strategies are names that
//! [`MassKind::parse`] reads, so a new strategy is measured by naming it.
//!
//! The error of a cell:
//! - the scene's reference solution, when it has one (`E_u`, `rms-position`,
//!   `max-relative-sigma-yy`; see [`psmpm::scene::Reference`]);
//! - `slide`: a scene without reference whose only wall condition is one straight
//!   slip wall (`fix = ["normal"]`), with gravity, starting at rest, is a body sliding
//!   without friction: its centre of mass moves along the wall by
//!   `s = ½ |g_t| t²`, `g_t` the gravity's component along the wall; the error is
//!   `|s_run − s| / s`, `s_run` the mean particle displacement along `g_t`; a
//!   slide error of [`SLIDE_BOUND`] or more makes the cell not stable;
//! - otherwise `energy-growth`: the largest growth of the total energy over the run,
//!   relative to the energy scale (what the stability verdict bounds by 0.05); none
//!   for a run that failed in its first step.
//!
//! The error of a run that stopped is the one at the step it stopped.
//!
//! σ_yy roughness (column cases: reference `column-self-weight` or
//! `column-equilibrium`): the RMS over particles of the second divided difference of
//! σ_yy along each vertical column of the particle lattice (in the initial height),
//! times the lattice spacing squared, relative to `|σ_yy(0)| = H ρ |g|`. On a
//! regular lattice it is the measure of `psmpm::reproduction::sigma_yy_roughness`;
//! on a jittered lattice the divided difference keeps a linear profile at zero.
//! `roughness` is measured at the end time; `roughness_rms` is its RMS over
//! [`ROUGHNESS_SAMPLES`] states of the run, the first after each time
//! `k t_end / ROUGHNESS_SAMPLES`, `k = 1 …`. The undamped column (B5b) oscillates
//! and its roughness grows and falls with the oscillation, so one instant is one
//! sample of a fluctuating quantity (on B5b 1 × 8 at 72 particles per triangle the
//! default's roughness ranges over 2.8e-2–5.7e-2 in the second half of the run).
//!
//! Runs go to up to `--jobs` threads, the most expensive first; each run is
//! single-threaded and deterministic, so every column but the wall time is the same
//! whatever the number of threads, and the rows come in case order.

use crate::error::CliError;
use crate::progress::Progress;
use crate::run::read_scene;
use crate::table::{sci, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::mass::MassKind;
use psmpm::scene::{Component, InitialVelocity, Reference, Scene};
use psmpm::simulation::{self, RunError, Summary, STABLE_CONDITION, STABLE_ENERGY_GROWTH};
use serde::Serialize;
use std::cmp::Ordering;
use std::path::{Path, PathBuf};
use std::sync::atomic::{self, AtomicUsize};
use std::sync::Mutex;

/// The cases of `--cases quick`: one of each kind that runs in seconds.
pub const QUICK: [&str; 4] = [
    "b2-nx5",
    "b4-ppe16-h0.25",
    "b5b-blocks-1x8-p12",
    "free-incline",
];

/// The strategies measured by default.
pub const DEFAULT_MASS: &str = "consistent,lumped,partial,deactivate";

/// Arguments of `mpm-cli stability`.
#[derive(Debug, clap::Args)]
pub struct StabilityArgs {
    /// Cases: `quick` (one of each kind, seconds), `all` (every scene file in the
    /// directory), or comma-separated case names; a name that is not a case selects
    /// the cases starting with it and a dash (`b5b`, `b5b-jitter`).
    #[arg(long, default_value = "quick")]
    cases: String,
    /// Mass strategies, comma-separated, as `--mass` of `mpm-cli run` reads them.
    #[arg(long, value_delimiter = ',', default_value = DEFAULT_MASS)]
    mass: Vec<String>,
    /// Bases, comma-separated (`ps,pl`; `bspline,pl1d` for the 1D cases): each case
    /// runs with those of its dimension, on its own mesh and particles (default:
    /// the basis of the case's file). A case with no basis of its dimension in the
    /// list runs with its own, and standard error says so.
    #[arg(long, value_delimiter = ',')]
    basis: Vec<String>,
    /// Directory of the case files (default: the repository's scenes/stability).
    #[arg(long, value_name = "DIR")]
    dir: Option<PathBuf>,
    /// Runs at the same time (default: the number of cores).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::whole::<usize>("1 or more"))]
    jobs: Option<usize>,
    /// Exit with status 1 when a case is unstable (default: 0, the table marks it).
    #[arg(long)]
    strict: bool,
    /// Threads of the particle phases, shared by the runs at the same time
    /// (default: all cores). The results are the same for any number.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = crate::whole::<usize>(crate::THREADS_RANGE))]
    threads: Option<usize>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// One cell of the matrix.
#[derive(Debug, Clone, Serialize)]
pub struct Cell {
    /// Case name (its file's stem).
    pub case: String,
    /// Basis.
    pub basis: &'static str,
    /// Mass strategy, as the run names it (`deactivate:0.01`).
    pub mass: String,
    /// The verdict of the run (no failure, energy growth and condition bounded).
    pub stable: bool,
    /// The run reached its end time.
    pub completed: bool,
    /// Why it is not stable: the failure with its step, or the bound it broke.
    pub reason: Option<String>,
    /// What `error` measures.
    pub measure: &'static str,
    /// Error against the case's reference (see the module doc).
    pub error: Option<f64>,
    /// σ_yy roughness at the end time (column cases).
    pub roughness: Option<f64>,
    /// RMS of the σ_yy roughness over [`ROUGHNESS_SAMPLES`] states of the run
    /// (column cases).
    pub roughness_rms: Option<f64>,
    /// Largest condition estimate of the mass systems.
    pub max_condition: Option<f64>,
    /// Largest number of lumped rows in a step.
    pub lumped_rows: usize,
    /// Largest number of deactivated functions in a step.
    pub deactivated: usize,
    /// Basis functions.
    pub functions: usize,
    /// Particles.
    pub particles: usize,
    /// Steps taken.
    pub steps: usize,
    /// Time step.
    pub dt: f64,
    /// Time reached.
    pub t_end: f64,
    /// Largest energy growth relative to the energy scale.
    pub energy_growth: f64,
    /// Wall time per step, in microseconds.
    pub us_per_step: f64,
    /// Wall time of the time loop, in seconds.
    pub seconds: f64,
}

/// The case directory of the repository this binary was built from.
fn default_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/stability")
}

/// Orders names with their digit runs compared as numbers (`nx2` before `nx17`).
fn natural(a: &str, b: &str) -> Ordering {
    fn chunks(s: &str) -> Vec<(bool, &str)> {
        let mut out = Vec::new();
        let mut start = 0;
        let bytes = s.as_bytes();
        for i in 1..=bytes.len() {
            if i == bytes.len() || bytes[i].is_ascii_digit() != bytes[start].is_ascii_digit() {
                out.push((bytes[start].is_ascii_digit(), &s[start..i]));
                start = i;
            }
        }
        out
    }
    let (ca, cb) = (chunks(a), chunks(b));
    for (x, y) in ca.iter().zip(&cb) {
        let o = match (x, y) {
            ((true, p), (true, q)) => {
                let (p, q) = (p.trim_start_matches('0'), q.trim_start_matches('0'));
                p.len().cmp(&q.len()).then(p.cmp(q))
            }
            ((_, p), (_, q)) => p.cmp(q),
        };
        if o != Ordering::Equal {
            return o;
        }
    }
    ca.len().cmp(&cb.len()).then(a.cmp(b))
}

/// Every case in `dir`: `(name, path)` in natural order of the names.
fn list_cases(dir: &Path) -> Result<Vec<(String, PathBuf)>, CliError> {
    let entries = std::fs::read_dir(dir)
        .map_err(|e| CliError::Input(format!("--dir {}: cannot read: {e}", dir.display())))?;
    let mut cases: Vec<(String, PathBuf)> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .filter_map(|p| Some((p.file_stem()?.to_str()?.to_string(), p.clone())))
        .collect();
    cases.sort_by(|a, b| natural(&a.0, &b.0));
    if cases.is_empty() {
        return Err(CliError::Input(format!(
            "--dir {}: no case files (*.toml)",
            dir.display()
        )));
    }
    Ok(cases)
}

/// The cases `--cases` selects, in natural order.
fn select(spec: &str, all: &[(String, PathBuf)]) -> Result<Vec<(String, PathBuf)>, CliError> {
    let wanted: Vec<&str> = match spec {
        "all" => return Ok(all.to_vec()),
        "quick" => QUICK.to_vec(),
        list => list.split(',').map(str::trim).collect(),
    };
    let mut chosen = vec![false; all.len()];
    for w in wanted {
        let mut hit = false;
        for (k, (name, _)) in all.iter().enumerate() {
            if name == w || name.starts_with(&format!("{w}-")) {
                chosen[k] = true;
                hit = true;
            }
        }
        if !hit {
            let names: Vec<&str> = all.iter().map(|(n, _)| n.as_str()).collect();
            return Err(CliError::Input(format!(
                "--cases: unknown case `{}` (known: quick, all, {})",
                psmpm::scene::limits::echo(w),
                names.join(", ")
            )));
        }
    }
    Ok(all
        .iter()
        .zip(&chosen)
        .filter(|(_, c)| **c)
        .map(|(case, _)| case.clone())
        .collect())
}

/// The unit normal of the scene's only slip wall, when the scene is a frictionless
/// slide (see the module doc): no reference, gravity, at rest, one boundary
/// condition and it is `normal`.
fn slide_normal(scene: &Scene) -> Option<[f64; 2]> {
    if scene.reference.is_some()
        || scene.dim != 2
        || scene.boundaries.len() != 1
        || scene.boundaries[0].fix != [Component::Normal]
        || scene.gravity().is_none()
    {
        return None;
    }
    let at_rest = match &scene.initial_velocity {
        InitialVelocity::Rest {} => true,
        InitialVelocity::Uniform { value } => value.iter().all(|v| *v == 0.0),
        _ => false,
    };
    if !at_rest {
        return None;
    }
    let mesh = simulation::triangulation(scene).ok()?;
    let id = mesh.tag_id(&scene.boundaries[0].tag).ok()?;
    let e = mesh.edges().iter().find(|e| e.tag == Some(id))?;
    let d = mesh.vertices()[e.vertices[1]] - mesh.vertices()[e.vertices[0]];
    let n = nalgebra::Vector2::new(d[1], -d[0]).normalize();
    Some([n[0], n[1]])
}

/// A column case: its reference is the column's (self-weight or equilibrium).
fn is_column(scene: &Scene) -> bool {
    matches!(
        scene.reference,
        Some(Reference::ColumnSelfWeight {}) | Some(Reference::ColumnEquilibrium {})
    )
}

/// σ_yy roughness of a column (see the module doc), `None` for other scenes.
fn column_roughness(scene: &Scene, p: &psmpm::particles::Particles<f64, 2>) -> Option<f64> {
    if !is_column(scene) {
        return None;
    }
    let body = &scene.bodies[0];
    let (hx, hy) = (
        scene.lattice_spacing(body, 0)?,
        scene.lattice_spacing(body, 1)?,
    );
    let height = body.max[1] - body.min[1];
    let g = scene.gravity()?[1].abs();
    let sigma0 = height * scene.material.density * g;
    let column = |k: usize| ((p.x0[k][0] - body.min[0]) / hx).floor() as i64;
    let mut order: Vec<usize> = (0..p.len()).collect();
    order.sort_by(|&a, &b| {
        column(a)
            .cmp(&column(b))
            .then(p.x0[a][1].total_cmp(&p.x0[b][1]))
    });
    let (mut sum, mut count) = (0.0, 0usize);
    for run in order.chunk_by(|&a, &b| column(a) == column(b)) {
        for w in run.windows(3) {
            let (y, s) = (|k: usize| p.x0[w[k]][1], |k: usize| p.sigma[w[k]][(1, 1)]);
            let slope = |i: usize, j: usize| (s(j) - s(i)) / (y(j) - y(i));
            let d = 2.0 * (slope(1, 2) - slope(0, 1)) / (y(2) - y(0)) * hy * hy;
            sum += d * d;
            count += 1;
        }
    }
    (count > 0).then(|| (sum / count as f64).sqrt() / sigma0)
}

/// The slide error: `|s_run − s| / s` (see the module doc).
fn slide_error(
    scene: &Scene,
    normal: [f64; 2],
    p: &psmpm::particles::Particles<f64, 2>,
    t: f64,
) -> Option<f64> {
    let g = scene.gravity()?;
    let gn = g[0] * normal[0] + g[1] * normal[1];
    let gt = [g[0] - gn * normal[0], g[1] - gn * normal[1]];
    let along = gt[0].hypot(gt[1]);
    if along == 0.0 || p.is_empty() || t <= 0.0 {
        return None;
    }
    let mass: f64 = p.mass.iter().sum();
    let mean =
        p.u.iter()
            .zip(&p.mass)
            .fold([0.0; 2], |a, (u, m)| [a[0] + m * u[0], a[1] + m * u[1]]);
    let s_run = (mean[0] * gt[0] + mean[1] * gt[1]) / (mass * along);
    let s = 0.5 * along * t * t;
    Some((s_run - s).abs() / s)
}

/// A rough cost of a run (particles and functions times steps), to start the
/// expensive runs first.
fn cost(scene: &Scene) -> f64 {
    let particles = simulation::particle_lattice(scene)
        .map(|l| l.positions.len())
        .unwrap_or(0) as f64;
    let (steps, vertices) = match simulation::triangulation(scene) {
        Ok(mesh) => {
            let h = mesh
                .edges()
                .iter()
                .map(|e| (mesh.vertices()[e.vertices[0]] - mesh.vertices()[e.vertices[1]]).norm())
                .fold(f64::INFINITY, f64::min);
            (scene.time.t_end / scene.dt(h), mesh.vertices().len() as f64)
        }
        Err(_) => (scene.steps() as f64, 0.0),
    };
    steps * (particles + 10.0 * vertices)
}

/// Why a run is not stable (`None` if it is).
fn reason(s: &Summary) -> Option<String> {
    if s.stable {
        return None;
    }
    if let Some(f) = &s.failure {
        return Some(f.clone());
    }
    let mut why = Vec::new();
    // NaN counts as above a bound, as in the verdict.
    let above = |x: f64, bound: f64| x.partial_cmp(&bound) != Some(Ordering::Less);
    if let Some(c) = s.max_condition.filter(|c| above(*c, STABLE_CONDITION)) {
        why.push(format!(
            "condition estimate {} above the bound {}",
            sci(c),
            sci(STABLE_CONDITION)
        ));
    }
    if above(s.energy_growth_centred, STABLE_ENERGY_GROWTH) {
        why.push(format!(
            "energy growth {} above the bound {} (time-centred total)",
            sci(s.energy_growth_centred),
            STABLE_ENERGY_GROWTH
        ));
    }
    Some(why.join("; "))
}

/// The energy growth of a run that took a step (nothing to measure before).
fn growth(s: &Summary) -> Option<f64> {
    (s.steps > 0).then_some(s.energy_growth)
}

/// States of a column run whose roughness `roughness_rms` averages.
pub const ROUGHNESS_SAMPLES: usize = 50;

/// A slide (measure `slide`) whose centre of mass is off `½ |g_t| t²` by this
/// fraction or more is not stable: the body did not slide as a frictionless one does
/// (e.g. a strategy that deactivated the functions carrying it, which then stands
/// still with its energy bounded).
pub const SLIDE_BOUND: f64 = 0.05;

/// Runs one cell.
fn run_cell(case: &str, scene: &Scene, on_step: &mut dyn FnMut()) -> Result<Cell, RunError> {
    let (summary, error, measure, roughness, roughness_rms) = if scene.dim == 2 {
        // The roughness of the first state after each `k t_end / ROUGHNESS_SAMPLES`.
        let column = is_column(scene);
        // (a relative 1e-9 below, so that the end state is the last sample)
        let sample_time =
            |k: usize| (k as f64 / ROUGHNESS_SAMPLES as f64 - 1e-9) * scene.time.t_end;
        let (mut next, mut sum, mut samples) = (1usize, 0.0, 0usize);
        let out = simulation::observe_2d(scene, &mut |r, p| {
            if r.step == 0 {
                return;
            }
            on_step();
            let psmpm::simulation::ParticlesRef::Two(p) = p else {
                return;
            };
            if !column || next > ROUGHNESS_SAMPLES || r.time < sample_time(next) {
                return;
            }
            while next <= ROUGHNESS_SAMPLES && r.time >= sample_time(next) {
                next += 1;
            }
            if let Some(rough) = column_roughness(scene, p) {
                sum += rough * rough;
                samples += 1;
            }
        })?;
        let roughness_rms = (samples > 0).then(|| (sum / samples as f64).sqrt());
        let s = out.summary;
        let roughness = column_roughness(scene, &out.particles);
        let (error, measure) = match (s.error_measure, slide_normal(scene)) {
            (Some(m), _) => (s.error, m),
            (None, Some(n)) => (slide_error(scene, n, &out.particles, s.t_end), "slide"),
            (None, None) => (growth(&s), "energy-growth"),
        };
        (s, error, measure, roughness, roughness_rms)
    } else {
        let s = simulation::run(scene, &mut |_| on_step())?;
        let (error, measure) = match s.error_measure {
            Some(m) => (s.error, m),
            None => (growth(&s), "energy-growth"),
        };
        (s, error, measure, None, None)
    };
    // NaN counts as above the bound, as in the verdict.
    let off =
        error.filter(|e| measure == "slide" && e.partial_cmp(&SLIDE_BOUND) != Some(Ordering::Less));
    Ok(Cell {
        case: case.to_string(),
        basis: summary.basis,
        mass: summary.mass.clone(),
        stable: summary.stable && off.is_none(),
        completed: summary.failure.is_none(),
        reason: reason(&summary).or_else(|| {
            off.map(|e| {
                format!(
                    "slide error {} above the bound {SLIDE_BOUND}: the body did not slide as a frictionless one does",
                    sci(e)
                )
            })
        }),
        measure,
        error,
        roughness,
        roughness_rms,
        max_condition: summary.max_condition,
        lumped_rows: summary.max_lumped_rows,
        deactivated: summary.max_deactivated,
        functions: summary.functions,
        particles: summary.particles,
        steps: summary.steps,
        dt: summary.dt,
        t_end: summary.t_end,
        energy_growth: summary.energy_growth,
        us_per_step: 1e6 * summary.seconds / summary.steps.max(1) as f64,
        seconds: summary.seconds,
    })
}

/// Runs every case with every strategy, up to `jobs` at the same time, their
/// steps on `pool`; cells in case order, strategies in the order given.
pub fn run_matrix(
    cases: &[(String, Scene)],
    masses: &[MassKind],
    jobs: usize,
    pool: &psmpm::threads::ThreadPool,
) -> Result<Vec<Cell>, CliError> {
    let mut cells: Vec<(String, Scene)> = Vec::new();
    for (name, scene) in cases {
        for &m in masses {
            let mut s = scene.clone();
            s.mass = m;
            cells.push((name.clone(), s));
        }
    }
    let costs: Vec<f64> = cells.iter().map(|(_, s)| cost(s)).collect();
    let mut order: Vec<usize> = (0..cells.len()).collect();
    order.sort_by(|&a, &b| costs[b].total_cmp(&costs[a]).then(a.cmp(&b)));
    let progress = Progress::new(cells.len() as u64, "runs");
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<Cell, RunError>>>> = Mutex::new(vec![None; cells.len()]);
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, cells.len().max(1)) {
            scope.spawn(|| loop {
                let k = next.fetch_add(1, atomic::Ordering::SeqCst);
                let Some(&i) = order.get(k) else { break };
                let (name, scene) = &cells[i];
                let r = pool.install(|| run_cell(name, scene, &mut || {}));
                progress.inc(1);
                if let Ok(mut all) = results.lock() {
                    all[i] = Some(r);
                }
            });
        }
    });
    progress.finish();
    let results = results.into_inner().unwrap_or_default();
    let mut out = Vec::with_capacity(results.len());
    for (r, (name, _)) in results.into_iter().zip(&cells) {
        match r {
            Some(Ok(cell)) => out.push(cell),
            Some(Err(e)) => return Err(CliError::Input(format!("case {name}: {e}"))),
            None => {
                return Err(CliError::Input(format!(
                    "case {name}: the run did not finish"
                )))
            }
        }
    }
    Ok(out)
}

const COLUMNS: [&str; 15] = [
    "case",
    "basis",
    "mass",
    "stable",
    "error",
    "measure",
    "roughness",
    "roughness_rms",
    "max_condition",
    "lumped",
    "deactivated",
    "functions",
    "particles",
    "steps",
    "us_per_step",
];

fn opt(x: Option<f64>) -> String {
    x.map_or_else(|| "-".into(), sci)
}

/// Prints the matrix.
pub fn print(cells: &[Cell], format: Format, jobs: usize) {
    match format {
        Format::Json => {
            let all = serde_json::to_value(cells).unwrap_or_default();
            println!("{all}");
        }
        Format::Csv => {
            println!(
                "case,basis,mass,stable,completed,reason,measure,error,roughness,roughness_rms,max_condition,lumped,deactivated,functions,particles,steps,dt,t_end,energy_growth,us_per_step,seconds"
            );
            let o = |x: Option<f64>| x.map_or_else(String::new, |v| v.to_string());
            for c in cells {
                let record = [
                    c.case.clone(),
                    c.basis.to_string(),
                    c.mass.clone(),
                    c.stable.to_string(),
                    c.completed.to_string(),
                    c.reason.clone().unwrap_or_default(),
                    c.measure.to_string(),
                    o(c.error),
                    o(c.roughness),
                    o(c.roughness_rms),
                    o(c.max_condition),
                    c.lumped_rows.to_string(),
                    c.deactivated.to_string(),
                    c.functions.to_string(),
                    c.particles.to_string(),
                    c.steps.to_string(),
                    c.dt.to_string(),
                    c.t_end.to_string(),
                    c.energy_growth.to_string(),
                    c.us_per_step.to_string(),
                    c.seconds.to_string(),
                ];
                println!("{}", crate::out::csv_record(&record));
            }
        }
        Format::Table => {
            let mut table = Table::new(&COLUMNS);
            for c in cells {
                table.push(vec![
                    c.case.clone(),
                    c.basis.to_string(),
                    c.mass.clone(),
                    match (c.stable, c.completed) {
                        (true, _) => "yes",
                        (false, true) => "NO*",
                        (false, false) => "NO",
                    }
                    .to_string(),
                    opt(c.error),
                    c.measure.to_string(),
                    opt(c.roughness),
                    opt(c.roughness_rms),
                    opt(c.max_condition),
                    c.lumped_rows.to_string(),
                    c.deactivated.to_string(),
                    c.functions.to_string(),
                    c.particles.to_string(),
                    c.steps.to_string(),
                    format!("{:.0}", c.us_per_step),
                ]);
            }
            print!("{}", table.render());
            let stable = cells.iter().filter(|c| c.stable).count();
            println!(
                "{} cells, {stable} stable; NO: the run stopped, NO*: it completed but broke a bound of the verdict; the error of a stopped run is the one where it stopped; wall times measured side by side on {jobs} {}",
                cells.len(),
                if jobs == 1 { "thread" } else { "threads" }
            );
            for c in cells {
                if let Some(r) = &c.reason {
                    println!("{} {}: {r}", c.case, c.mass);
                }
            }
        }
    }
}

/// Runs `mpm-cli stability`.
pub fn stability(args: StabilityArgs) -> Result<(), CliError> {
    let masses: Vec<MassKind> = args
        .mass
        .iter()
        .map(|m| MassKind::parse(m.trim()).map_err(|e| CliError::Input(format!("--mass: {e}"))))
        .collect::<Result<_, _>>()?;
    if masses.is_empty() {
        return Err(CliError::Input("--mass: lists no strategy".into()));
    }
    let jobs = args.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    if jobs == 0 {
        return Err(CliError::Input("--jobs must be at least 1".into()));
    }
    let dir = args.dir.clone().unwrap_or_else(default_dir);
    let all = list_cases(&dir)?;
    let bases: Vec<BasisKind> = args
        .basis
        .iter()
        .map(|b| BasisKind::parse(b.trim()).map_err(|e| CliError::Input(format!("--basis: {e}"))))
        .collect::<Result<_, _>>()?;
    let mut cases = Vec::new();
    for (name, path) in select(&args.cases, &all)? {
        let scene = read_scene(&path.to_string_lossy())?;
        let of_dim: Vec<BasisKind> = bases
            .iter()
            .copied()
            .filter(|b| b.dim() == scene.dim)
            .collect();
        if of_dim.is_empty() {
            if !bases.is_empty() {
                eprintln!(
                    "note: case {name} is {}D and --basis names no {}D basis: it runs with its own, {}",
                    scene.dim,
                    scene.dim,
                    scene.basis.name()
                );
            }
            cases.push((name, scene));
            continue;
        }
        for basis in of_dim {
            let mut s = scene.clone();
            s.basis = basis;
            cases.push((name.clone(), s));
        }
    }
    let pool = crate::run::thread_pool(args.threads)?;
    let cells = run_matrix(&cases, &masses, jobs, &pool)?;
    print(&cells, args.format, jobs);
    let failed = cells.iter().filter(|c| !c.stable).count();
    crate::error::study_verdict(args.strict, failed, cells.len())
}

#[cfg(test)]
mod tests {
    use super::natural;
    use std::cmp::Ordering;

    #[test]
    fn natural_order_compares_numbers() {
        let mut names = vec![
            "b2-nx17",
            "b2-nx2",
            "b5b-blocks-2x16-p12",
            "b5b-blocks-1x8-p72",
            "b4-ppe16-h0.0625",
            "b4-ppe16-h0.25",
            "b4-ppe16-h0.125",
        ];
        names.sort_by(|a, b| natural(a, b));
        assert_eq!(
            names,
            [
                "b2-nx2",
                "b2-nx17",
                "b4-ppe16-h0.25",
                "b4-ppe16-h0.125",
                "b4-ppe16-h0.0625",
                "b5b-blocks-1x8-p72",
                "b5b-blocks-2x16-p12",
            ]
        );
        assert_eq!(natural("a", "a"), Ordering::Equal);
    }
}
