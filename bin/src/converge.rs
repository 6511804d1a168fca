//! `mpm-cli converge`: a refinement study of a scene for several bases: error,
//! observed order and wall time per level, the project's answer to "what does
//! accuracy cost in time".
//!
//! Level `l` refines the scene as its `[study]` says (block counts times `2^l`).
//! Runs are sequential so that their wall times are comparable.

use crate::compare::variants;
use crate::error::CliError;
use crate::run::{read_scene, Overrides};
use crate::table::{fixed2, sci, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::output::chart::{line_plot, Axis, LinePlot, Scale, Series, SeriesStyle};
use psmpm::particles::Particles;
use psmpm::scene::limits::echo;
use psmpm::scene::{BodyShape, Scene};
use psmpm::simulation::{self, RunError, Summary};
use psmpm::studies::self_convergence::{error_against, FinestField};
use serde::Serialize;
use serde_json::{json, Value};
use std::path::PathBuf;

/// Arguments of `mpm-cli converge`.
#[derive(Debug, clap::Args)]
pub struct ConvergeArgs {
    /// Built-in scene (see `mpm-cli scenes`) or a scene file FILE.toml.
    scene: String,
    /// Bases, comma-separated (default: ps,pl in 2D, bspline,pl1d in 1D).
    #[arg(long, value_delimiter = ',')]
    basis: Vec<String>,
    /// Mass strategy (default: the scene's).
    #[arg(long)]
    mass: Option<String>,
    /// Number of levels (1 to 7).
    #[arg(long, default_value_t = 3, allow_hyphen_values = true, value_parser = crate::whole::<u32>("from 1 to 7"))]
    levels: u32,
    /// The factor (1 to 4) by which each level also multiplies the particles per
    /// element along each refined axis (replaces the scene's
    /// `study.particle_growth`; default: the scene's, else 1, particles per element
    /// stay). At fixed particles per element PS's error is set by the particle
    /// quadrature and stops falling with h; 2 shows its order.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = crate::whole::<u32>("from 1 to 4"))]
    particle_growth: Option<u32>,
    #[command(flatten)]
    overrides: Overrides,
    /// Write the table as CSV and JSON and the log-log error-vs-h and
    /// error-vs-wall-time plots (SVG) into this directory.
    /// DIR must be new, empty or hold only these files, checked before the study runs.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// With --out: replace the files of an earlier study in DIR (converge.csv,
    /// converge.json and the two plots). Without it a DIR that is not empty is
    /// refused; a DIR holding other files is refused even with it.
    #[arg(long, requires = "out")]
    overwrite: bool,
    /// Exit with status 1 when a variant failed or is unstable (default: 0, the
    /// table marks it).
    #[arg(long)]
    strict: bool,
    /// An error to reach: prints, per basis, the wall time at which its error
    /// falls to this value (log-log interpolation between the two levels around
    /// it) and how many times faster the fastest basis gets there (a
    /// work-precision comparison; `docs/performance.md`).
    #[arg(long, value_name = "ERROR", allow_hyphen_values = true)]
    target_error: Option<f64>,
    /// Threads of each run's particle phases (default: all cores; 1 for
    /// work-precision timings on a shared machine). The errors are the same for any
    /// number.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = crate::whole::<usize>(crate::THREADS_RANGE))]
    threads: Option<usize>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// The files `--out` writes.
const OUT_FILES: [&str; 4] = [
    "converge.csv",
    "converge.json",
    "error-vs-h.svg",
    "work-precision.svg",
];

/// The columns of the table and of `converge.csv`.
const COLUMNS: [&str; 11] = [
    "basis",
    "level",
    "h",
    "functions",
    "particles",
    "dt",
    "steps",
    "error",
    "order",
    "seconds",
    "stable",
];

/// One level of the study.
#[derive(Debug, Clone, Serialize)]
pub struct Level {
    /// Basis.
    pub basis: &'static str,
    /// Level (0 = the scene's resolution).
    pub level: u32,
    /// Mesh size.
    pub h: f64,
    /// Basis functions.
    pub functions: usize,
    /// Particles.
    pub particles: usize,
    /// Time step (with `courant`, it shrinks with `h`).
    pub dt: f64,
    /// Steps taken (fewer than planned when the run stopped early).
    pub steps: usize,
    /// Error against the reference; `None` when the run stopped before its end
    /// time (an error at another time is not comparable with the other levels').
    pub error: Option<f64>,
    /// Observed order against the previous level with an error.
    pub order: Option<f64>,
    /// Wall time of the run.
    pub seconds: f64,
    /// Stable verdict.
    pub stable: bool,
    /// The run stopped before its end time (a failed step).
    pub stopped: bool,
}

/// When a basis's error reaches a target error ([`ConvergeArgs::target_error`]).
#[derive(Debug, Clone, Serialize)]
pub struct Reach {
    /// Basis.
    pub basis: &'static str,
    /// Wall time at which the error reaches the target: interpolated in log-log
    /// between the last level above it and the first at or below it; `None` when
    /// no stable level reaches it.
    pub seconds: Option<f64>,
    /// How `seconds` was found: `interpolated`, `at most` (the first level is
    /// already below the target) or `not reached`.
    pub how: &'static str,
}

/// Per basis, when its error reaches `target` (levels in order, stable ones only).
pub fn reaches(rows: &[Level], target: f64) -> Vec<Reach> {
    let mut bases: Vec<&'static str> = rows.iter().map(|r| r.basis).collect();
    bases.dedup();
    bases
        .into_iter()
        .map(|basis| {
            let points: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.basis == basis && r.stable && r.seconds > 0.0)
                .filter_map(|r| r.error.filter(|e| *e > 0.0).map(|e| (r.seconds, e)))
                .collect();
            let first = points.iter().position(|&(_, e)| e <= target);
            let (seconds, how) = match first {
                None => (None, "not reached"),
                Some(0) => (Some(points[0].0), "at most"),
                Some(i) => {
                    let ((t0, e0), (t1, e1)) = (points[i - 1], points[i]);
                    let slope = (t1.ln() - t0.ln()) / (e1.ln() - e0.ln());
                    (
                        Some((t0.ln() + (target.ln() - e0.ln()) * slope).exp()),
                        "interpolated",
                    )
                }
            };
            Reach {
                basis,
                seconds,
                how,
            }
        })
        .collect()
}

/// A target error and when each basis reaches it.
#[derive(Debug, Clone, Serialize)]
pub struct Target {
    /// The error to reach.
    pub error: f64,
    /// Per basis.
    pub reaches: Vec<Reach>,
}

/// Everything a study prints and writes.
struct Study<'a> {
    rows: &'a [Level],
    against: Against,
    diagnoses: &'a [Diagnosis],
    notes: &'a [String],
    target: Option<&'a Target>,
}

/// The lines saying when each basis reaches `target` and how much faster the
/// fastest one does.
fn reach_lines(target: f64, reaches: &[Reach]) -> String {
    let mut out = String::new();
    for r in reaches {
        out += &match (r.seconds, r.how) {
            (Some(t), "at most") => format!(
                "{} reaches error {target:.1e} at its first level: in at most {t:.3} s\n",
                r.basis
            ),
            (Some(t), _) => format!("{} reaches error {target:.1e} in {t:.3} s\n", r.basis),
            _ => format!(
                "{} does not reach error {target:.1e} on these levels\n",
                r.basis
            ),
        };
    }
    let mut timed: Vec<(&str, f64)> = reaches
        .iter()
        .filter_map(|r| r.seconds.map(|t| (r.basis, t)))
        .collect();
    timed.sort_by(|a, b| a.1.total_cmp(&b.1));
    if let Some(&(fastest, t)) = timed.first() {
        for &(other, u) in &timed[1..] {
            out += &format!("{fastest} reaches it {:.1}× faster than {other}\n", u / t);
        }
    }
    out
}

/// What the errors of a study are measured against.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Against {
    /// The scene's exact or reference solution.
    Exact,
    /// The finest level of the same basis (the scene has no exact solution).
    FinestLevel,
}

/// Why an order fell, measured by two extra runs at the level where it fell.
#[derive(Debug, Clone, Serialize)]
pub struct Diagnosis {
    /// Basis.
    pub basis: &'static str,
    /// The level whose order fell.
    pub level: u32,
    /// Its order.
    pub order: f64,
    /// Error of that level with half the time step, over its error.
    pub half_dt: Option<f64>,
    /// Error of that level with a quarter of the time step, over its error:
    /// measured when half the step lowered the error, to see whether it falls again.
    pub quarter_dt: Option<f64>,
    /// Error of that level with twice the particles along every axis, over its error.
    pub double_particles: Option<f64>,
    /// What limits the error, and what to change.
    pub verdict: String,
}

/// A probe that lowers the error by more than this fraction names what limits it.
const LIMITING_GAIN: f64 = 0.2;

/// The largest fall of the error that one halving of the time step can give when
/// the step limits it: × 0.25 for a second-order scheme (the central difference),
/// × 0.5 for a first-order one, with room for the other errors. A halving that
/// lowers the error more is not the time integration's error falling.
const STEPWISE_FALL: f64 = 0.15;

/// An order falls when it is below this…
const LOW_ORDER: f64 = 0.5;
/// …or this far below the best order the basis reached on the coarser levels.
const ORDER_DROP: f64 = 0.5;

/// A level's final particles, kept to measure the coarser levels against the finest.
enum Final {
    One(Particles<f64, 1>),
    Two(Particles<f64, 2>),
}

/// The finest level's field, in the scene's dimension.
enum Finest {
    One(FinestField<1>),
    Two(FinestField<2>),
}

impl Finest {
    fn new(particles: &Final) -> Result<Self, String> {
        Ok(match particles {
            Final::One(p) => Finest::One(FinestField::new(p).map_err(|e| e.to_string())?),
            Final::Two(p) => Finest::Two(FinestField::new(p).map_err(|e| e.to_string())?),
        })
    }

    fn error(&self, particles: &Final) -> Option<f64> {
        match (self, particles) {
            (Finest::One(f), Final::One(p)) => Some(error_against(f, p)),
            (Finest::Two(f), Final::Two(p)) => Some(error_against(f, p)),
            _ => None,
        }
    }
}

/// Runs `scene`, level `level` of the study of `args`, and keeps its final particles
/// when the run reached its end. A set-up error names the scene, the level and the
/// basis, and the flags that set its field.
fn run_level(
    args: &ConvergeArgs,
    level: usize,
    scene: &Scene,
) -> Result<(Summary, Option<Final>), CliError> {
    let err = |e: RunError| {
        let e = match e {
            RunError::Scene(e) => {
                let flags = args.overrides.flags_of(&e);
                if flags.is_empty() {
                    e.to_string()
                } else {
                    format!("{} (from {})", e, flags.join(" "))
                }
            }
            other => other.to_string(),
        };
        CliError::Input(format!(
            "{}: level {level} ({}, h = {}): {e}",
            echo(&args.scene),
            scene.basis.name(),
            scene.mesh_size().map_or_else(|| "-".into(), sci),
        ))
    };
    let (summary, particles) = if scene.dim == 1 {
        let o = simulation::run_1d(scene, &mut |_| {}).map_err(err)?;
        (o.summary, Final::One(o.particles))
    } else {
        let o = simulation::run_2d(scene, &mut |_| {}).map_err(err)?;
        (o.summary, Final::Two(o.particles))
    };
    let finished = summary.failure.is_none() && !summary.interrupted;
    Ok((summary, finished.then_some(particles)))
}

/// The scenes of the study, validated before any runs: per basis (and mass), its
/// levels in order; and what the errors are measured against.
fn levels(args: &ConvergeArgs) -> Result<(Scene, Against, Vec<Vec<Scene>>), CliError> {
    if args.levels == 0 || args.levels > 7 {
        return Err(CliError::Input(format!(
            "--levels must be between 1 and 7, got {}",
            args.levels
        )));
    }
    crate::run::check_threads(args.threads)?;
    if let Some(growth) = args.particle_growth.filter(|g| !(1..=4).contains(g)) {
        return Err(CliError::Input(format!(
            "--particle-growth must be between 1 and 4, got {growth}"
        )));
    }
    if let Some(e) = args.target_error {
        if !(e.is_finite() && e > 0.0) {
            return Err(CliError::Input(format!(
                "--target-error must be a positive error, got {}",
                psmpm::scene::limits::echo_number(e)
            )));
        }
    }
    let base = read_scene(&args.scene)?;
    let against = if base.reference.is_some() {
        Against::Exact
    } else {
        if args.levels < 3 {
            return Err(CliError::Input(format!(
                "scene `{}` has no exact solution, so its levels are measured against the \
                 finest one: --levels must be at least 3 to give an order, got {}",
                base.name, args.levels
            )));
        }
        Against::FinestLevel
    };
    let masses: Vec<String> = args.mass.iter().cloned().collect();
    let mut bases = variants(&base, &args.basis, &masses, &args.overrides, &args.scene)?;
    if let Some(growth) = args.particle_growth {
        for scene in &mut bases {
            scene.study.particle_growth = Some(growth);
        }
    }
    let levels = bases
        .iter()
        .map(|scene| {
            (0..args.levels)
                .map(|level| {
                    scene.refined(level).map_err(|e| {
                        CliError::Input(if args.scene.ends_with(".toml") {
                            format!(
                                "{} (level {level} of the study)",
                                crate::run::locate(&args.scene, &e)
                            )
                        } else {
                            format!("level {level}: {e}")
                        })
                    })
                })
                .collect::<Result<Vec<_>, _>>()
        })
        .collect::<Result<Vec<_>, _>>()?;
    Ok((base, against, levels))
}

/// Every scene the study would run, validated ([`crate::check`]).
pub fn prepare(args: &ConvergeArgs) -> Result<Vec<Scene>, CliError> {
    Ok(levels(args)?.2.into_iter().flatten().collect())
}

/// Runs the study and prints it.
pub fn converge(args: ConvergeArgs) -> Result<(), CliError> {
    let (base, against, scenes) = levels(&args)?;
    if let Some(dir) = &args.out {
        crate::out::prepare_out(dir, args.overwrite, |name| OUT_FILES.contains(&name))?;
    }
    let pool = crate::run::thread_pool(args.threads)?;
    pool.install(|| study(&args, base, against, scenes))
}

/// The runs of [`converge`], on the current pool.
fn study(
    args: &ConvergeArgs,
    base: Scene,
    against: Against,
    scenes: Vec<Vec<Scene>>,
) -> Result<(), CliError> {
    let mut rows: Vec<Level> = Vec::new();
    let mut diagnoses: Vec<Diagnosis> = Vec::new();
    let mut notes: Vec<String> = Vec::new();
    // What `run` warns about, per level (on standard error, before the table).
    let mut warnings: Vec<String> = Vec::new();
    let progress =
        crate::progress::Progress::new(scenes.iter().map(Vec::len).sum::<usize>() as u64, "runs");
    for variant in scenes {
        let mut levels = Vec::new();
        let mut finals = Vec::new();
        for (level, s) in variant.into_iter().enumerate() {
            let (summary, particles) = run_level(args, level, &s)?;
            progress.inc(1);
            warnings.extend(
                summary
                    .warnings
                    .iter()
                    .map(|w| format!("warning ({} level {level}): {w}", summary.basis)),
            );
            levels.push((s, summary));
            finals.push(particles);
        }
        if let (Against::FinestLevel, Some((_, last))) = (against, levels.last()) {
            if last.failure.is_none() && !last.stable {
                notes.push(format!(
                    "{}: the finest level, against which every error of this basis is \
                     measured, is not stable ({}): its errors measure the distance to that \
                     run, not to the solution",
                    last.basis,
                    crate::run::unstable_reason(last),
                ));
            }
        }
        let finest = match against {
            Against::Exact => None,
            Against::FinestLevel => match finals.last().and_then(|f| f.as_ref()) {
                Some(f) => match Finest::new(f) {
                    Ok(field) => Some(field),
                    Err(e) => {
                        notes.push(format!("{}: no error: {e}", levels[0].1.basis));
                        None
                    }
                },
                None => {
                    notes.push(format!(
                        "{}: the finest level did not reach the end, so no level has an error",
                        levels[0].1.basis
                    ));
                    None
                }
            },
        };
        let error_of = |summary: &Summary, particles: &Option<Final>| match against {
            Against::Exact => particles.as_ref().and(summary.error),
            Against::FinestLevel => match (&finest, particles) {
                (Some(f), Some(p)) => f.error(p),
                _ => None,
            },
        };
        let mut previous: Option<(f64, f64)> = None;
        let mut best_order = f64::NEG_INFINITY;
        let mut falling: Option<(usize, f64)> = None;
        let first = rows.len();
        for (index, ((s, summary), particles)) in levels.iter().zip(&finals).enumerate() {
            let is_finest = against == Against::FinestLevel && index + 1 == levels.len();
            let error = if is_finest {
                None
            } else {
                error_of(summary, particles)
            };
            let h = s.mesh_size().unwrap_or(f64::NAN);
            if let Some(failure) = &summary.failure {
                notes.push(format!(
                    "{} level {index}: stopped at t = {:.4} of {}, so it has no error and gives no \
                     order: {failure}",
                    summary.basis,
                    summary.t_end,
                    s.time.t_end,
                ));
            } else if error.is_some() && !summary.stable {
                notes.push(format!(
                    "{} level {index}: not stable ({}); its error and order are shown, and \
                     drawn apart in the plots",
                    summary.basis,
                    crate::run::unstable_reason(summary),
                ));
            }
            let order = match (previous, error) {
                (Some((h0, e0)), Some(e)) if e > 0.0 && e0 > 0.0 => {
                    Some((e0 / e).ln() / (h0 / h).ln())
                }
                _ => None,
            };
            if let Some(p) = order {
                if summary.stable && (p < LOW_ORDER || p < best_order - ORDER_DROP) {
                    falling = Some((index, p));
                }
                best_order = best_order.max(p);
            }
            if let Some(e) = error {
                previous = Some((h, e));
            }
            rows.push(Level {
                basis: summary.basis,
                level: index as u32,
                h,
                functions: summary.functions,
                particles: summary.particles,
                dt: summary.dt,
                steps: summary.steps,
                error,
                order,
                seconds: summary.seconds,
                stable: summary.stable,
                stopped: summary.failure.is_some(),
            });
        }
        if let Some((index, order)) = falling {
            let error = rows[first + index].error.unwrap_or(f64::NAN);
            let probe = |s: Scene| -> Result<Option<f64>, CliError> {
                let (summary, particles) = run_level(args, index, &s)?;
                Ok(error_of(&summary, &particles).map(|e| e / error))
            };
            let s = &levels[index].0;
            let half = with_half_time_step(s);
            let half_dt = probe(half.clone())?;
            // One halving that lowers the error may be chance (the error of a level
            // varies with any change to its run): the step limits the error only if
            // a second halving lowers it again.
            let quarter_dt = match half_dt {
                Some(r) if r < 1.0 - LIMITING_GAIN => probe(with_half_time_step(&half))?,
                _ => None,
            };
            let double_particles = match with_double_particles(s) {
                Some(denser) => probe(denser)?,
                None => None,
            };
            diagnoses.push(Diagnosis {
                basis: rows[first].basis,
                level: index as u32,
                order,
                half_dt,
                quarter_dt,
                double_particles,
                verdict: on_edges_first(
                    &levels[index].1,
                    verdict(s, half_dt, quarter_dt, double_particles),
                ),
            });
        }
    }
    progress.finish();
    for warning in &warnings {
        eprintln!("{warning}");
    }
    let target = args.target_error.map(|e| Target {
        error: e,
        reaches: reaches(&rows, e),
    });
    let study = Study {
        rows: &rows,
        against,
        diagnoses: &diagnoses,
        notes: &notes,
        target: target.as_ref(),
    };
    print_levels(&study, args.format);
    if let Some(dir) = &args.out {
        write_outputs(dir, &base.name, &study)?;
    }
    let failed = rows.iter().filter(|r| !r.stable).count();
    crate::error::study_verdict(args.strict, failed, rows.len())
}

/// `scene` with half its time step (half its Courant number).
fn with_half_time_step(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    if let Some(dt) = &mut s.time.dt {
        *dt *= 0.5;
    }
    if let Some(c) = &mut s.time.courant {
        *c *= 0.5;
    }
    s
}

/// `scene` with twice the particles of every body along every axis (per block or
/// per axis counts doubled, a lattice spacing halved, a Gmsh body's triangles split
/// once more: four times the particles in 2D), or `None` when a body gives its
/// particles otherwise.
fn with_double_particles(scene: &Scene) -> Option<Scene> {
    let mut s = scene.clone();
    for body in &mut s.bodies {
        if let Some(counts) = body.per_block.as_mut().or(body.count.as_mut()) {
            counts.iter_mut().for_each(|n| *n *= 2);
        } else if let Some(spacing) = body.spacing.as_mut() {
            spacing.iter_mut().for_each(|h| *h *= 0.5);
        } else if body.shape == BodyShape::Gmsh {
            body.subdivide = Some(body.subdivide.unwrap_or(0) + 1);
        } else {
            return None;
        }
    }
    Some(s)
}

/// Whether halving the time step lowers the error consistently: `half` and
/// `quarter` are the errors with half and a quarter of the step over the level's
/// error. Each halving must lower the error beyond the noise ([`LIMITING_GAIN`])
/// and by no more than the scheme's order allows ([`STEPWISE_FALL`]).
fn falls_with_the_step(half: Option<f64>, quarter: Option<f64>) -> bool {
    let consistent = |r: f64| (STEPWISE_FALL..1.0 - LIMITING_GAIN).contains(&r);
    match (half, quarter) {
        (Some(h), Some(q)) if h > 0.0 => consistent(h) && consistent(q / h),
        _ => false,
    }
}

/// What the probes say limits the error at a level whose order fell: half the
/// The text PL's warning about particles on element edges starts its share with
/// (`simulation::pl_edge_particles_warning`).
const ON_EDGES: &str = "lie on element edges or vertices at the start";

/// `verdict`, preceded by the cause the level's run warned about, if it did:
/// particles on PL's element edges at the start. A user's PL study at `[4, 4]`
/// (half its particles on the block diagonals, orders 0.57, 0.20, 0.05) was told
/// of particles crossing element edges, where the motion was 1 % of an element and
/// each level's warning named the lattice.
fn on_edges_first(summary: &Summary, verdict: String) -> String {
    match summary.warnings.iter().find(|w| w.contains(ON_EDGES)) {
        Some(_) => format!(
            "this level's particles start on element edges (its warning above): PL's gradient \
             jumps there and each such particle takes one side's, an error that does not fall \
             with h; give a lattice whose rows miss the edges (`per_block` with one odd and \
             one even count, such as [3, 4]) and study again. Else: {verdict}"
        ),
        None => verdict,
    }
}

/// time step (and, when that lowered the error, a quarter of it) and twice the
/// particles, each as the error over the level's error. The step is said to limit
/// the error only when both halvings lower it by a factor a first- or second-order
/// scheme gives ([`falls_with_the_step`]); one halving that helped and a second
/// that did not says that the step is not what limits it.
fn verdict(
    scene: &Scene,
    half_dt: Option<f64>,
    quarter_dt: Option<f64>,
    double_particles: Option<f64>,
) -> String {
    let lowers = |r: Option<f64>| r.is_some_and(|r| r < 1.0 - LIMITING_GAIN);
    // PL's gradient jumps across element edges; the 2D PS and the 1D B-spline
    // bases are smooth.
    let smooth = matches!(scene.basis, BasisKind::Ps | BasisKind::Bspline);
    let crossing = if smooth {
        ""
    } else {
        "; with a C⁰ basis such as PL also the error of particles that crossed element \
         edges during the run, which their stress keeps (where the level's run warned of \
         crossings; a smooth basis, ps or bspline, avoids it)"
    };
    let time = if scene.time.courant.is_some() {
        "a smaller `courant` (--courant, or --dt)"
    } else {
        "a smaller `dt` (--dt), or `courant` (--courant) so that the step shrinks with h"
    };
    // The growth already in effect is not offered again (a user's study run with
    // `--particle-growth 2` was told to add it).
    let growth = scene.study.particle_growth.unwrap_or(1);
    let particles = if growth > 1 {
        format!(
            "more particles per element at every level (`--particles`, or `per_block` / \
             `count`: the particles already grow {growth} times along each refined axis per \
             level, `--particle-growth {growth}`)"
        )
    } else {
        "more particles per element as h shrinks (`--particle-growth 2`, or \
         `particle_growth = 2` in `[study]`, doubles them along each refined axis per level)"
            .to_string()
    };
    // Against an exact solution the finest level has no error of its own to blame.
    let finest = if scene.reference.is_some() {
        ""
    } else {
        ", the finest level's error"
    };
    // An error of second order in the motion: the update moves the particles over
    // a fixed grid, so its equations are not linear in the displacement even
    // where the reference is (a user's PL1D bar at t = 0.15: a floor of 8.5e-8
    // from 64 to 144 elements, the same at half the step and twice the particles,
    // four times larger at twice the amplitude).
    let amplitude = "an error of second order in the motion, which the update's particles \
                     moving over a fixed grid make and a linear reference does not have (run \
                     the level at half the amplitude: such an error falls four times)";
    let step_limits = falls_with_the_step(half_dt, quarter_dt);
    // Half the step lowered the error far more than the scheme's order allows and
    // the next halving raised it again: the time integration's error and the
    // mesh's were of a size and of opposite signs, and cancelled at one step (a
    // user's B-spline bar at 2e-11: × 0.02, then × 12.3).
    if let (Some(h), Some(q)) = (half_dt, quarter_dt) {
        if h < STEPWISE_FALL && q / h > 1.0 + LIMITING_GAIN {
            return format!(
                "half the step lowers the error more than the step's order allows and the \
                 next halving raises it again (× {:.2}): at this level the time \
                 integration's error and the mesh's are of one size and of opposite signs, \
                 and cancel in part at some steps, so the level's error is the time \
                 integration's, not the mesh's: {time} at every level shows the mesh's order",
                q / h
            );
        }
    }
    // Half the step lowered the error, but not consistently with the step.
    let not_the_step = match (half_dt, quarter_dt) {
        (Some(h), Some(q)) if lowers(half_dt) && !step_limits => format!(
            "the error does not fall consistently with the step (half of it × {h:.2}, then the \
             next halving × {:.2}), so the time step is not what limits it and a smaller one \
             will not help; ",
            q / h
        ),
        _ => String::new(),
    };
    let limits = match (step_limits, lowers(double_particles)) {
        (true, true) => format!(
            "both the time step and the particles per element limit the error: {time} and {particles}"
        ),
        (true, false) => format!("the time step limits the error: {time}"),
        (false, true) if !smooth => format!(
            "the particles per element limit the error (particle quadrature of the internal \
             force; with a C⁰ basis such as PL above all the error of particles crossing \
             element edges, each crossing a jump of the gradient they see, which falls with \
             the particles per element and not with h, so that at fixed particles per element \
             the order stays low or turns negative once the motion is a sizeable part of an \
             element): {particles}, or a smooth basis (bspline, ps), which has no such jumps"
        ),
        (false, true) => format!(
            "the particles per element limit the error (particle quadrature of the internal \
             force): {particles}"
        ),
        (false, false) if double_particles.is_some_and(|r| r > 1.0 + LIMITING_GAIN) => {
            if smooth && scene.reference.is_some() {
                "more particles raise the error, so neither h, dt nor quadrature limits it: \
                 the reference's own assumptions may (check that the scene is the case its \
                 `[reference]` describes: its loads, its fixed ends, small strain)"
                    .into()
            } else if smooth {
                "more particles raise the error, so neither h, dt nor quadrature limits it: \
                 the reference's own error may (against the finest level, that level's; give \
                 the scene a `[reference]` where one exists)"
                    .into()
            } else {
                "more particles raise the error: the error of particles crossing element \
                 edges (largest for a C⁰ basis such as PL), not h, dt or quadrature; a smooth \
                 basis (ps, bspline) avoids it"
                    .into()
            }
        }
        (false, false) if !not_the_step.is_empty() => format!(
            "nor do more particles lower it: it has reached a floor that refinement does not \
             remove (for example the reference's own assumptions, such as small strain{finest}, \
             {amplitude}, or an error that changes with the instants at which particles cross \
             element edges){crossing}"
        ),
        (false, false) => format!(
            "neither a smaller time step nor more particles lower the error by more than \
             a fifth: it has reached a floor that refinement does not remove (for example \
             the reference's own assumptions, such as small strain{finest}, or {amplitude}){crossing}"
        ),
    };
    format!("{not_the_step}{limits}")
}

/// The study as JSON: what the errors are measured against, the levels, the
/// diagnoses of falling orders and the notes.
fn json(study: &Study) -> Value {
    json!({
        "against": study.against,
        "levels": study.rows,
        "diagnoses": study.diagnoses,
        "notes": study.notes,
        "target": study.target,
    })
}

/// The lines printed under the table: what the error is, and why orders fell.
fn explanation(study: &Study) -> String {
    let (against, diagnoses, notes) = (study.against, study.diagnoses, study.notes);
    let mut out = String::new();
    if against == Against::FinestLevel {
        out += "note: the error is E_u against the finest level of the same basis (the \
                scene has no exact solution), so the finest level has none\n";
    }
    for n in notes {
        out += &format!("note: {n}\n");
    }
    let ratio = |r: Option<f64>| r.map_or_else(|| "not measured".into(), |r| format!("× {r:.2}"));
    for d in diagnoses {
        out += &format!(
            "{} level {}: the order falls to {:.2}. At this level, half the time step \
             changes the error {}{}, twice the particles along each axis {}: {}.\n",
            d.basis,
            d.level,
            d.order,
            ratio(d.half_dt),
            d.quarter_dt
                .map_or_else(String::new, |r| format!(", a quarter of it × {r:.2}")),
            ratio(d.double_particles),
            d.verdict
        );
    }
    if let Some(t) = study.target {
        out += &reach_lines(t.error, &t.reaches);
    }
    out
}

fn print_levels(study: &Study, format: Format) {
    let rows = study.rows;
    match format {
        Format::Json => println!("{}", json(study)),
        Format::Csv => {
            print!("{}", csv(rows));
            for line in explanation(study).lines() {
                eprintln!("# {line}");
            }
        }
        Format::Table => {
            let mut table = Table::new(&COLUMNS);
            for r in rows {
                table.push(vec![
                    r.basis.to_string(),
                    r.level.to_string(),
                    sci(r.h),
                    r.functions.to_string(),
                    r.particles.to_string(),
                    sci(r.dt),
                    r.steps.to_string(),
                    r.error.map_or_else(|| "-".into(), sci),
                    fixed2(r.order),
                    format!("{:.3}", r.seconds),
                    match (r.stable, r.stopped) {
                        (_, true) => "stopped",
                        (true, false) => "yes",
                        (false, false) => "NO",
                    }
                    .to_string(),
                ]);
            }
            print!("{}", table.render());
            print!("{}", explanation(study));
        }
    }
}

fn csv(rows: &[Level]) -> String {
    // Every digit, in exponent form as in `diagnostics.csv` (not `0.0000000000224…`).
    let float = |x: f64| format!("{x:e}");
    let opt = |v: Option<f64>| v.map_or_else(String::new, float);
    let mut out = crate::out::csv_record(&COLUMNS);
    out.push('\n');
    for r in rows {
        out += &crate::out::csv_record(&[
            r.basis.to_string(),
            r.level.to_string(),
            float(r.h),
            r.functions.to_string(),
            r.particles.to_string(),
            float(r.dt),
            r.steps.to_string(),
            opt(r.error),
            opt(r.order),
            float(r.seconds),
            r.stable.to_string(),
        ]);
        out.push('\n');
    }
    out
}

/// `converge.csv`, `converge.json`, `error-vs-h.svg`, `work-precision.svg`.
/// Per basis with two stable levels or more, a guide of the slope its degree
/// gives the displacement error (`h^(p+1)`: 3 for the quadratic PS and B-spline
/// bases, 2 for PL) through its finest stable level, over its levels' mesh sizes:
/// the order read off the plot against the one the theory gives.
fn reference_slopes(rows: &[Level]) -> Vec<Series> {
    let mut bases: Vec<&str> = rows.iter().map(|r| r.basis).collect();
    bases.dedup();
    bases
        .into_iter()
        .filter_map(|b| {
            let stable: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.basis == b && r.stable)
                .filter_map(|r| r.error.map(|e| (r.h, e)))
                .filter(|(h, e)| *h > 0.0 && *e > 0.0)
                .collect();
            let order = match BasisKind::parse(b).ok()? {
                BasisKind::Ps | BasisKind::Bspline => 3,
                BasisKind::Pl | BasisKind::Pl1d => 2,
            };
            let &(h0, e0) = stable.iter().min_by(|a, b| a.0.total_cmp(&b.0))?;
            let h1 = stable.iter().map(|p| p.0).fold(h0, f64::max);
            (h1 > h0).then(|| {
                Series::new(
                    format!("slope {order} ({} reference)", b.to_uppercase()),
                    [(h0, e0), (h1, e0 * (h1 / h0).powi(order))],
                    SeriesStyle::Guide,
                )
            })
        })
        .collect()
}

fn write_outputs(dir: &std::path::Path, scene: &str, study: &Study) -> Result<(), CliError> {
    let (rows, against) = (study.rows, study.against);
    let io = |path: &std::path::Path, e: std::io::Error| {
        CliError::Input(format!("{}: cannot write: {e}", path.display()))
    };
    let path = dir.join("converge.csv");
    std::fs::write(&path, csv(rows)).map_err(|e| io(&path, e))?;
    let path = dir.join("converge.json");
    let json = serde_json::to_string_pretty(&json(study)).unwrap_or_default();
    std::fs::write(&path, json).map_err(|e| io(&path, e))?;
    let mut bases: Vec<&str> = rows.iter().map(|r| r.basis).collect();
    bases.dedup();
    // Per basis, its stable levels as a curve and its unstable ones as markers of a
    // series of their own (levels that stopped early have no error to draw).
    let curves = |x: &dyn Fn(&Level) -> f64| -> Vec<Series> {
        let points = |b: &str, stable: bool| -> Vec<(f64, f64)> {
            rows.iter()
                .filter(|r| r.basis == b && r.stable == stable)
                .filter_map(|r| r.error.map(|e| (x(r), e)))
                .filter(|(x, e)| *x > 0.0 && *e > 0.0)
                .collect()
        };
        let mut series = Vec::new();
        for b in &bases {
            series.push(Series {
                name: b.to_uppercase(),
                points: points(b, true),
                style: SeriesStyle::LineAndMarkers,
            });
            let unstable = points(b, false);
            if !unstable.is_empty() {
                series.push(Series {
                    name: format!("{} (not stable)", b.to_uppercase()),
                    points: unstable,
                    style: SeriesStyle::Markers,
                });
            }
        }
        series
    };
    let mut against_h = curves(&|r| r.h);
    against_h.extend(reference_slopes(rows));
    let plots = [
        (
            "error-vs-h.svg",
            format!("{scene}: error against mesh size"),
            "mesh size h",
            against_h,
        ),
        (
            "work-precision.svg",
            format!("{scene}: error against wall time"),
            "wall time (s)",
            curves(&|r| r.seconds),
        ),
    ];
    for (file, title, x_label, series) in plots {
        let plot = LinePlot {
            title,
            x: Axis {
                label: x_label.into(),
                scale: Scale::Log10,
                include: None,
            },
            y: Axis {
                label: match against {
                    Against::Exact => "error".into(),
                    Against::FinestLevel => "error against the finest level".into(),
                },
                scale: Scale::Log10,
                include: None,
            },
            series,
            size: (800, 600),
        };
        let path = dir.join(file);
        line_plot(&path, &plot).map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn level(basis: &'static str, seconds: f64, error: f64, stable: bool) -> Level {
        Level {
            basis,
            level: 0,
            h: 1.0,
            functions: 1,
            particles: 1,
            dt: 1e-3,
            steps: 1,
            error: Some(error),
            order: None,
            seconds,
            stable,
            stopped: false,
        }
    }

    #[test]
    fn the_time_to_an_error_is_interpolated_in_log_log() {
        let rows = [
            level("ps", 1.0, 1e-4, true),
            level("ps", 10.0, 1e-6, true),
            level("pl", 2.0, 1e-6, true),
            level("bspline", 1.0, 1e-3, true),
            level("bspline", 5.0, 1e-7, false),
        ];
        let r = reaches(&rows, 1e-5);
        assert_eq!(r.len(), 3);
        // Halfway in log error is halfway in log time: √10 s.
        assert_eq!(r[0].how, "interpolated");
        assert!((r[0].seconds.unwrap() - 10f64.sqrt()).abs() < 1e-12);
        // Already below at its first level: at most its time.
        assert_eq!((r[1].seconds, r[1].how), (Some(2.0), "at most"));
        // An unstable level does not count.
        assert_eq!((r[2].seconds, r[2].how), (None, "not reached"));
        let lines = reach_lines(1e-5, &r);
        assert!(
            lines.contains("pl reaches it 1.6× faster than ps"),
            "{lines}"
        );
        assert!(lines.contains("bspline does not reach"), "{lines}");
    }

    /// A user's 1D column (pl1d, level 3 of `--blocks 4x1`): half the step lowered
    /// the error × 0.52, but a quarter of it × 0.54 (halving again: × 1.03, and
    /// courant 0.125, 0.0625, 0.03125 gave 0.54, 0.49, 0.45 of the level's error).
    /// The study said "the time step limits the error: a smaller `courant`"; it
    /// now says that the step is not what limits it.
    #[test]
    fn the_step_limits_the_error_only_if_it_falls_with_each_halving() {
        let scene = Scene::builtin("column-small-1d").unwrap();
        let once = verdict(&scene, Some(0.52), Some(0.54), Some(1.05));
        assert!(!once.contains("the time step limits"), "{once}");
        assert!(
            once.starts_with("the error does not fall consistently with the step (half of it × 0.52, then the next halving × 1.04)")
                && once.contains("nor do more particles lower it"),
            "{once}"
        );
        let with_particles = verdict(&scene, Some(0.52), Some(0.54), Some(0.4));
        assert!(
            with_particles
                .contains("a smaller one will not help; the particles per element limit the error"),
            "{with_particles}"
        );
        // First order (× 0.5 twice) and second order (× 0.25 twice) limit it.
        for r in [0.5, 0.25] {
            let v = verdict(&scene, Some(r), Some(r * r), Some(1.0));
            assert!(v.starts_with("the time step limits the error"), "{v}");
        }
        // Falling far more than a second-order scheme can is not the step's error.
        assert!(!falls_with_the_step(Some(0.05), Some(0.0025)));
        // A halving within the noise does not count, nor one probe alone.
        assert!(!falls_with_the_step(Some(0.85), Some(0.7)));
        assert!(!falls_with_the_step(Some(0.5), None));
        let unmeasured = verdict(&scene, Some(0.5), None, Some(1.0));
        assert!(!unmeasured.contains("the time step limits"), "{unmeasured}");
    }

    /// A user's B-spline bar at 2.2e-11 (`bar1d-vib-small`, 16 particles per
    /// element, level 3): half the step × 0.02, a quarter × 0.23, twice the
    /// particles × 1.23. The study said the step was not what limited the error and
    /// pointed at the reference; the time and mesh errors cancelled at half the
    /// step, and a fixed smaller `dt` gave clean orders (1.99, 2.00, 2.02).
    #[test]
    fn errors_that_cancel_at_half_the_step_are_named_the_time_steps() {
        let scene = Scene::builtin("vibrating-bar-1d").unwrap();
        let v = verdict(&scene, Some(0.02), Some(0.23), Some(1.23));
        assert!(
            v.starts_with("half the step lowers the error more than the step's order allows and the next halving raises it again (× 11.50)")
                && v.contains("a smaller `dt` (--dt)")
                && !v.contains("reference"),
            "{v}"
        );
        // C⁰ bases are told about crossing when particles limit the error.
        let mut pl = scene.clone();
        pl.basis = BasisKind::Pl1d;
        let v = verdict(&pl, Some(0.87), Some(0.8), Some(0.49));
        assert!(
            v.contains("crossing element edges") && v.contains("or a smooth basis"),
            "{v}"
        );
    }
    /// A teacher's PL1D bar (2026-12-08, `--particle-growth 2`, a floor at t =
    /// 0.15 that neither half the step nor twice the particles moved) was told to
    /// add `--particle-growth 2`, which the study already had, and of "the finest
    /// level's error" in a study against the exact solution. The growth in effect
    /// is named instead, the finest level only without a reference, and an error
    /// of second order in the motion is offered with its check.
    #[test]
    fn the_advice_fits_the_study_it_is_given_to() {
        let mut scene = Scene::builtin("vibrating-bar-1d").unwrap();
        scene.basis = BasisKind::Pl1d;
        assert!(scene.reference.is_some());
        let floor = verdict(&scene, Some(1.0), None, Some(1.0));
        assert!(
            !floor.contains("the finest level's error")
                && floor.contains("run the level at half the amplitude"),
            "{floor}"
        );
        let mut unreferenced = scene.clone();
        unreferenced.reference = None;
        let floor = verdict(&unreferenced, Some(1.0), None, Some(1.0));
        assert!(floor.contains("the finest level's error"), "{floor}");
        scene.study.particle_growth = Some(2);
        let grown = verdict(&scene, Some(1.0), None, Some(0.5));
        assert!(
            grown.contains("the particles already grow 2 times")
                && !grown.contains("(`--particle-growth 2`, or"),
            "{grown}"
        );
    }
}
