//! `mpm-cli run`: run a scene and print per-step diagnostics and a summary.

use crate::error::CliError;
use crate::out::{self, Recorder};
use crate::progress::Progress;
use crate::table::{sci, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::driver::StepReport;
use psmpm::mass::MassKind;
use psmpm::particles::Particles;
use psmpm::scene::{parse_split, BlockLayout, MeshSpec, Scene};
use psmpm::simulation::{self, AsParticlesRef, ParticlesRef, RunError, Summary};
use serde_json::json;
use std::path::PathBuf;

/// The options that adjust a scene's resolution and time (shared by `run`,
/// `compare`, `converge`).
#[derive(Debug, Clone, clap::Args)]
pub struct Overrides {
    /// Block grid NXxNY of a block mesh (1D: number of elements, e.g. 8x1).
    #[arg(long, value_name = "NXxNY")]
    pub blocks: Option<String>,
    /// Particles per block PXxPY (1D: per element, e.g. 4x1).
    #[arg(long, value_name = "PXxPY")]
    pub particles: Option<String>,
    /// PS split points: incentre or centroid (the thesis' tables).
    #[arg(long)]
    pub split: Option<String>,
    /// Triangulation of each block: four-triangles (the seeds' grid) or delaunay
    /// (Delaunay of block corners and centres, the thesis' tables).
    #[arg(long)]
    pub layout: Option<String>,
    /// Time step (replaces the scene's dt or Courant number).
    #[arg(long)]
    pub dt: Option<f64>,
    /// End time.
    #[arg(long)]
    pub t_end: Option<f64>,
    /// Estimate the condition number of the solved mass system every step (about 60
    /// extra solves; 30 products for `extended`).
    #[arg(long)]
    pub condition: bool,
}

impl Overrides {
    /// Applies the overrides to `s` and validates it.
    pub fn apply(&self, mut s: Scene) -> Result<Scene, CliError> {
        let input = |e: psmpm::scene::SceneError| CliError::Input(e.to_string());
        if let Some(b) = &self.blocks {
            let (nx, ny) = pair(b, "--blocks")?;
            s.set_blocks(nx, ny).map_err(input)?;
        }
        if let Some(p) = &self.particles {
            let (px, py) = pair(p, "--particles")?;
            s.set_particles_per_block([px, py]);
        }
        if let Some(split) = &self.split {
            s.split = parse_split(split).map_err(|m| CliError::Input(format!("--split: {m}")))?;
        }
        if let Some(layout) = &self.layout {
            let l = match layout.as_str() {
                "four-triangles" => BlockLayout::FourTriangles,
                "delaunay" => BlockLayout::Delaunay,
                other => {
                    return Err(CliError::Input(format!(
                        "--layout: unknown layout `{other}` (known: four-triangles, delaunay)"
                    )))
                }
            };
            s.set_layout(l).map_err(input)?;
        }
        if let Some(dt) = self.dt {
            s.set_dt(dt);
        }
        if let Some(t) = self.t_end {
            s.time.t_end = t;
        }
        if self.condition {
            s.output.condition = true;
        }
        s.validate().map_err(input)?;
        Ok(s)
    }
}

/// Arguments of `mpm-cli run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Built-in scene (see `mpm-cli scenes`) or a scene file FILE.toml; the options
    /// below override the scene's values.
    scene: String,
    /// Basis: ps or pl (2D scenes), bspline or pl1d (1D scenes).
    #[arg(long)]
    basis: Option<String>,
    /// Mass strategy: default (= extended: under-supported functions expressed
    /// through well-covered neighbours), extended:C (coverage threshold C), consistent,
    /// lumped, partial (lump rows touching empty elements), partial:TAU (lump rows with
    /// M_ii < TAU·max M_jj), partial-coverage:C, deactivate, deactivate:THRESHOLD or fmpm:K.
    #[arg(long)]
    mass: Option<String>,
    #[command(flatten)]
    overrides: Overrides,
    /// Print diagnostics every N steps (0: summary only; default: the scene's
    /// `output.diagnostics_every`, else about 20 rows).
    #[arg(long)]
    diag_every: Option<usize>,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Write into DIR: diagnostics.csv (every step), summary.json, particle frames
    /// (particles.pvd for ParaView), mesh.vtu (2D), tracked.csv and tracked.svg
    /// (scenes with tracked particles) and energy.svg.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// With --out: a particle frame every N steps (default: about 50 frames; 0: the
    /// first and last state only, which are always written).
    #[arg(long, value_name = "N", requires = "out")]
    out_every: Option<usize>,
    /// Threads of the particle phases (default: all cores). The results are the
    /// same, bit for bit, for any number.
    #[arg(long, value_name = "N")]
    threads: Option<usize>,
}

/// Parses `AxB`.
pub fn pair(text: &str, what: &str) -> Result<(usize, usize), CliError> {
    let bad = || CliError::Input(format!("{what} must look like 4x1, got `{text}`"));
    let (a, b) = text.split_once('x').ok_or_else(bad)?;
    Ok((a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?))
}

/// A set-up error of a scene file, located in the file when it names a field.
pub fn locate(scene: &str, message: &str) -> String {
    if !scene.ends_with(".toml") {
        return message.to_string();
    }
    match std::fs::read_to_string(scene) {
        Ok(text) => psmpm::scene::locate_message(&text, scene, message),
        Err(_) => message.to_string(),
    }
}

/// Reads a scene: a built-in name or a `.toml` file (a relative Gmsh path in it is
/// taken relative to the file).
pub fn read_scene(name: &str) -> Result<Scene, CliError> {
    if name.ends_with(".toml") {
        let text = std::fs::read_to_string(name)
            .map_err(|e| CliError::Input(format!("{name}: cannot read: {e}")))?;
        let mut s = Scene::from_toml(&text, name).map_err(|e| CliError::Input(e.to_string()))?;
        if let MeshSpec::Gmsh { file } = &mut s.mesh {
            let path = std::path::Path::new(file.as_str());
            if path.is_relative() {
                if let Some(dir) = std::path::Path::new(name).parent() {
                    *file = dir.join(path).to_string_lossy().into_owned();
                }
            }
        }
        Ok(s)
    } else {
        Scene::builtin(name).map_err(CliError::Input)
    }
}

/// The scene of `run` with the command line's choices applied, validated.
fn scene(args: &RunArgs) -> Result<Scene, CliError> {
    let mut s = read_scene(&args.scene)?;
    if let Some(b) = &args.basis {
        s.basis = BasisKind::parse(b).map_err(|m| CliError::Input(format!("--basis: {m}")))?;
    }
    if let Some(m) = &args.mass {
        s.mass = MassKind::parse(m).map_err(|m| CliError::Input(format!("--mass: {m}")))?;
    }
    args.overrides.apply(s)
}

fn row_json(r: &StepReport) -> serde_json::Value {
    json!({
        "step": r.step,
        "time": r.time,
        "kinetic": r.kinetic,
        "strain": r.strain,
        "potential": r.potential,
        "work": r.work,
        "total": r.total_energy(),
        "mass": r.mass,
        "momentum": r.momentum,
        "max_speed": r.max_speed,
        "active": r.mass_report.active,
        "lumped_rows": r.mass_report.lumped_rows,
        "deactivated": r.mass_report.deactivated,
        "extended": r.mass_report.extended,
        "treated": r.mass_report.treated(),
        "worst_coverage": r.mass_report.worst_coverage.map(|(f, c)| json!({"function": f, "coverage": c})),
        "condition": r.condition,
    })
}

const COLUMNS: [&str; 10] = [
    "step",
    "time",
    "kinetic",
    "strain",
    "potential",
    "total",
    "max_speed",
    "active",
    "lumped",
    "condition",
];

fn row_csv(r: &StepReport) -> String {
    [
        r.step.to_string(),
        r.time.to_string(),
        r.kinetic.to_string(),
        r.strain.to_string(),
        r.potential.to_string(),
        r.total_energy().to_string(),
        r.max_speed.to_string(),
        r.mass_report.active.to_string(),
        r.mass_report.lumped_rows.to_string(),
        r.condition.map_or_else(String::new, |c| c.to_string()),
    ]
    .join(",")
}

fn row_cells(r: &StepReport) -> Vec<String> {
    vec![
        r.step.to_string(),
        format!("{:.4}", r.time),
        sci(r.kinetic),
        sci(r.strain),
        sci(r.potential),
        sci(r.total_energy()),
        sci(r.max_speed),
        r.mass_report.active.to_string(),
        r.mass_report.lumped_rows.to_string(),
        r.condition.map_or_else(|| "-".into(), sci),
    ]
}

/// Runs the scene and prints diagnostics and the summary (and writes the files of
/// `--out`).
pub fn run(args: RunArgs) -> Result<(), CliError> {
    let pool = thread_pool(args.threads)?;
    pool.install(move || run_on_pool(args))
}

/// The pool of `--threads N` (`None`: one thread per core).
pub fn thread_pool(threads: Option<usize>) -> Result<psmpm::threads::ThreadPool, CliError> {
    if threads == Some(0) {
        return Err(CliError::Input("--threads must be at least 1".into()));
    }
    psmpm::threads::pool(threads)
        .map_err(|e| CliError::Input(format!("--threads: no thread pool ({e})")))
}

/// [`run`] on the current thread pool.
fn run_on_pool(args: RunArgs) -> Result<(), CliError> {
    let s = scene(&args)?;
    let every = args
        .diag_every
        .unwrap_or(if s.output.diagnostics_every > 0 {
            s.output.diagnostics_every
        } else {
            (s.steps() / 20).max(1)
        });
    let mut recorder = match &args.out {
        Some(dir) => Some(Recorder::create(dir, args.out_every, &s)?),
        None => None,
    };
    let progress = Progress::new(s.steps() as u64, "steps");
    let t_end = s.time.t_end;
    let mut table = Table::new(&COLUMNS);
    let format = args.format;
    let mut csv_header = true;
    let mut observer = |r: &StepReport, particles: ParticlesRef<'_>| {
        if let Some(recorder) = recorder.as_mut() {
            recorder.observe(r, particles);
        }
        if r.step == 0 {
            return;
        }
        if r.step == 1 && r.time > 0.0 {
            progress.set_total(out::steps_from_dt(t_end, r.time) as u64);
        }
        progress.inc(1);
        if every > 0 && r.step % every == 0 {
            match format {
                Format::Json => println!("{}", row_json(r)),
                Format::Csv => {
                    if std::mem::take(&mut csv_header) {
                        println!("{}", COLUMNS.join(","));
                    }
                    println!("{}", row_csv(r));
                }
                Format::Table => table.push(row_cells(r)),
            }
        }
    };
    let setup = |e: RunError| match e {
        RunError::Setup(m) => CliError::Input(locate(&args.scene, &m)),
    };
    let (summary, tracked, last) = match s.dim {
        2 => {
            let o = simulation::observe_2d(&s, &mut observer).map_err(setup)?;
            (o.summary, o.tracked, Last::Two(o.particles))
        }
        _ => {
            let o = simulation::observe_1d(&s, &mut observer).map_err(setup)?;
            (o.summary, o.tracked, Last::One(o.particles))
        }
    };
    progress.finish();
    let written = recorder.map(|r| {
        let dir = r.path().to_path_buf();
        r.finish(&summary, &tracked, last.view())
            .map(|files| out::files_line(&dir, &files))
    });
    match format {
        Format::Json => println!("{}", summary_json(&summary)),
        Format::Csv => {}
        Format::Table => {
            if every > 0 {
                print!("{}", table.render());
                println!();
            }
            print!("{}", summary_text(&summary));
        }
    }
    if let Some(written) = written {
        let line = written?;
        // stdout stays machine-readable for --format json and csv.
        match format {
            Format::Table => println!("{line}"),
            Format::Json | Format::Csv => eprintln!("{line}"),
        }
    }
    match &summary.failure {
        Some(reason) => Err(CliError::Numerical(reason.clone())),
        None => Ok(()),
    }
}

/// The particles at the end of a run, in its dimension.
enum Last {
    One(Particles<f64, 1>),
    Two(Particles<f64, 2>),
}

impl Last {
    fn view(&self) -> ParticlesRef<'_> {
        match self {
            Last::One(p) => p.view(),
            Last::Two(p) => p.view(),
        }
    }
}

/// The summary as one JSON object.
pub fn summary_json(summary: &Summary) -> serde_json::Value {
    serde_json::to_value(summary).unwrap_or_else(|e| json!({ "error": e.to_string() }))
}

/// The summary for reading at a glance.
pub fn summary_text(summary: &Summary) -> String {
    let mut out = String::new();
    out += &format!(
        "{} · {} · {} mass · {} functions · {} particles · {} steps of {} to t = {}\n",
        summary.scene,
        summary.basis,
        summary.mass,
        summary.functions,
        summary.particles,
        summary.steps,
        sci(summary.dt),
        summary.t_end
    );
    let error = match (summary.error, summary.error_measure) {
        (Some(e), Some(m)) => format!("error {m} = {}", sci(e)),
        _ => "no reference solution".into(),
    };
    out += &format!(
        "{error} · {} · energy {} → {} (drift {:.2e}) · max condition {} · lumped rows ≤ {}\n",
        if summary.stable { "stable" } else { "UNSTABLE" },
        sci(summary.energy_initial),
        sci(summary.energy_final),
        summary.energy_drift,
        summary.max_condition.map_or("-".into(), sci),
        summary.max_lumped_rows,
    );
    if let Some(reason) = &summary.failure {
        out += &format!("stopped: {reason}\n");
    }
    let p = &summary.phases;
    let total = (p.evaluate + p.assemble + p.solve + p.update).max(f64::MIN_POSITIVE);
    out += &format!(
        "wall time {:.2} s ({:.1} µs/step): evaluate {:.0} % · assemble {:.0} % · solve {:.0} % · update {:.0} %\n",
        summary.seconds,
        1e6 * summary.seconds / summary.steps.max(1) as f64,
        100.0 * p.evaluate / total,
        100.0 * p.assemble / total,
        100.0 * p.solve / total,
        100.0 * p.update / total
    );
    out
}
