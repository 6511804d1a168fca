//! `mpm-cli run`: run a scene and print per-step diagnostics and a summary.

use crate::error::CliError;
use crate::out::{self, Recorder};
use crate::progress::Progress;
use crate::table::{sci, short, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::driver::StepReport;
use psmpm::mass::MassKind;
use psmpm::output::particle_picture::ParticleField;
use psmpm::output::vtk::VtuEncoding;
use psmpm::particles::Particles;
use psmpm::scene::limits::{echo, echo_number, plural, MAX_FRAMES, MAX_TABLE_ROWS, MAX_THREADS};
use psmpm::scene::{parse_mirror_line, parse_split, BlockLayout, BodyShape, Scene, SceneError};
use psmpm::simulation::{self, AsParticlesRef, ParticlesRef, RunError, Summary};
use serde_json::json;
use std::io::Write;
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The options that adjust a scene's resolution and time (shared by `run`,
/// `compare`, `converge`).
#[derive(Debug, Clone, clap::Args)]
pub struct Overrides {
    /// Block grid NXxNY of a block mesh (1D: number of elements, e.g. 8x1).
    #[arg(long, value_name = "NXxNY", allow_hyphen_values = true)]
    pub blocks: Option<String>,
    /// Particles per block PXxPY (1D: per element, e.g. 4x1).
    #[arg(long, value_name = "PXxPY", allow_hyphen_values = true)]
    pub particles: Option<String>,
    /// PS split points: incentre or centroid (the thesis' tables).
    #[arg(long)]
    pub split: Option<String>,
    /// PS: the mirror line the basis keeps where a vertex is symmetric about both
    /// axes (block grids): vertical (default), horizontal, diagonal (y − x =
    /// const) or anti-diagonal (x + y = const), the scene's own.
    #[arg(long, value_name = "LINE")]
    pub mirror_line: Option<String>,
    /// Triangulation of each block: four-triangles (the seeds' grid) or delaunay
    /// (Delaunay of block corners and centres, the thesis' tables).
    #[arg(long)]
    pub layout: Option<String>,
    /// Time step (replaces the scene's dt or Courant number).
    #[arg(long, allow_hyphen_values = true, conflicts_with = "courant", value_parser = crate::real)]
    pub dt: Option<f64>,
    /// Time step as a fraction C of the critical step estimated at the start,
    /// Δt = C Δt_crit (replaces the scene's dt or Courant number; below 1).
    #[arg(long, value_name = "C", allow_hyphen_values = true, value_parser = crate::real)]
    pub courant: Option<f64>,
    /// End time.
    #[arg(long, allow_hyphen_values = true, value_parser = crate::real)]
    pub t_end: Option<f64>,
    /// Run with a time step above the critical step estimated at the start (an error
    /// otherwise): to see what an unstable step does.
    #[arg(long)]
    pub allow_above_critical: bool,
    /// Keep every step whole: no new estimate of the critical step as the bodies
    /// move, no sub-steps where it falls (the scene's `time.watch = false`).
    #[arg(long)]
    pub no_watch: bool,
    /// Estimate the condition number of the solved mass system every step (about 60
    /// extra solves; 30 products for `extended`). The verdict then also requires it
    /// below 1e8, as in the stability matrix (docs/stability.md); without it the
    /// verdict judges completion and energy only, and says so.
    #[arg(long)]
    pub condition: bool,
}

/// Why `--particles` has no effect on a scene whose bodies are all Gmsh bodies.
const GMSH_BODIES_ONLY: &str = "every body is a Gmsh body (`shape = \"gmsh\"`), whose particles `per_triangle` and `subdivide` set; --particles sets the particles per block of box, polygon and disk bodies";

impl Overrides {
    /// Applies the overrides to `s`, read from `file` (a scene file or a built-in
    /// name), and validates it.
    pub fn apply(&self, mut s: Scene, file: &str) -> Result<Scene, CliError> {
        let dim = s.dim;
        let one_d = |flag: &str, text: &str, second: usize| {
            if dim == 1 && second != 1 {
                Err(CliError::Input(format!(
                    "{flag} {}: a 1D scene has one count; the second number must be 1 (e.g. 8x1), got {second}",
                    echo(text)
                )))
            } else {
                Ok(())
            }
        };
        if let Some(b) = &self.blocks {
            let (nx, ny) = pair(b, "--blocks")?;
            one_d("--blocks", b, ny)?;
            s.set_blocks(nx, ny)
                .map_err(|e| CliError::Input(format!("--blocks {}: {e}", echo(b))))?;
        }
        if let Some(p) = &self.particles {
            let (px, py) = pair(p, "--particles")?;
            one_d("--particles", p, py)?;
            if s.bodies.iter().all(|b| b.shape == BodyShape::Gmsh) {
                return Err(CliError::Input(format!(
                    "--particles {}: {GMSH_BODIES_ONLY}",
                    echo(p)
                )));
            }
            // Particles per block need blocks: say so in the flag's words (the
            // scene's field would be `per_block`, which the file did not give).
            if !matches!(
                s.mesh,
                psmpm::scene::MeshSpec::Blocks { .. } | psmpm::scene::MeshSpec::Interval { .. }
            ) {
                return Err(CliError::Input(format!(
                    "--particles {}: sets the particles per block, which needs a `blocks` or `interval` mesh; on this mesh set the bodies' particles in the scene file (`count` or `spacing`, or `per_triangle` for a Gmsh body)",
                    echo(p)
                )));
            }
            s.set_particles_per_block([px, py]);
        }
        if let Some(split) = &self.split {
            if dim == 1 {
                return Err(CliError::Input(format!(
                    "--split {}: a 1D scene has no triangles to split",
                    echo(split)
                )));
            }
            s.split = parse_split(split).map_err(|m| CliError::Input(format!("--split: {m}")))?;
        }
        if let Some(line) = &self.mirror_line {
            if dim == 1 {
                return Err(CliError::Input(format!(
                    "--mirror-line {}: a 1D scene has no control triangles",
                    echo(line)
                )));
            }
            s.mirror_line = parse_mirror_line(line)
                .map_err(|m| CliError::Input(format!("--mirror-line: {m}")))?;
        }
        if let Some(layout) = &self.layout {
            let l = match layout.as_str() {
                "four-triangles" => BlockLayout::FourTriangles,
                "delaunay" => BlockLayout::Delaunay,
                other => {
                    return Err(CliError::Input(format!(
                        "--layout: unknown layout `{}` (known: four-triangles, delaunay)",
                        echo(other)
                    )))
                }
            };
            s.set_layout(l)
                .map_err(|e| CliError::Input(format!("--layout {}: {e}", echo(layout))))?;
        }
        if let Some(dt) = self.dt {
            s.set_dt(dt);
        }
        if let Some(c) = self.courant {
            s.set_courant(c);
        }
        if self.allow_above_critical {
            s.time.allow_above_critical = true;
        }
        if self.no_watch {
            s.time.watch = false;
        }
        if let Some(t) = self.t_end {
            s.time.t_end = t;
        }
        if self.condition {
            s.output.condition = true;
        }
        s.validate()
            .map_err(|e| CliError::Input(self.name_flags(&e, file)))?;
        Ok(s)
    }

    /// A validation error after the overrides, prefixed by the flags (and values)
    /// that set the field, else located in the scene file `file`.
    fn name_flags(&self, e: &psmpm::scene::SceneError, file: &str) -> String {
        let flags = self.flags_of(e);
        if flags.is_empty() {
            locate(file, e)
        } else {
            format!("{}: {e}", flags.join(" "))
        }
    }

    /// The flags (and values) of these overrides that set the field of `e`.
    pub fn flags_of(&self, e: &psmpm::scene::SceneError) -> Vec<String> {
        let field = e.field.as_str();
        let mut flags = Vec::new();
        // The tracked history grows with the steps, which the time flags set.
        let history = field == "output.tracked" && e.message.contains("tracked points over");
        // The step's flags set `time.dt` and `time.courant`, and with the end time
        // the number of steps (an end time shorter than one step, the history);
        // `--t-end` sets only that. An error on a field no flag set is located in
        // the file instead.
        let steps = history || (field == "time.t_end" && e.message.contains("time step"));
        if (field.starts_with("time.") && field != "time.t_end") || steps {
            if let Some(dt) = self.dt {
                flags.push(format!("--dt {}", echo_number(dt)));
            }
            if let Some(c) = self.courant {
                flags.push(format!("--courant {}", echo_number(c)));
            }
        }
        // The number of steps (`t_end / dt`) is `--t-end`'s too.
        if field == "time.t_end"
            || history
            || (field.starts_with("time.") && e.message.contains("t_end"))
        {
            if let Some(t) = self.t_end {
                flags.push(format!("--t-end {}", echo_number(t)));
            }
        }
        // The critical step depends on the mesh.
        if field.starts_with("mesh.") || (field == "time.dt" && e.message.contains("critical")) {
            if let Some(b) = &self.blocks {
                flags.push(format!("--blocks {}", echo(b)));
            }
        }
        if field.starts_with("body") || field == "material.density" {
            if let Some(p) = &self.particles {
                flags.push(format!("--particles {}", echo(p)));
            }
        }
        flags
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
    /// Mass strategy: default (= extended-hybrid: functions with almost no particles
    /// expressed through well-covered neighbours, poorly covered rows lumped except
    /// for what an affine field sees), extended-hybrid:C1:C2[:W] (W: the functions a
    /// wall constrains extended, not lumped, below coverage W), extended[:C] (coverage
    /// threshold C), consistent, lumped, partial (lump rows touching empty elements),
    /// partial:TAU (lump rows with M_ii < TAU·max M_jj), partial-coverage:C,
    /// deactivate, deactivate:THRESHOLD, extended-hybrid-apic|-rpic|-plain or fmpm:K.
    #[arg(long)]
    mass: Option<String>,
    #[command(flatten)]
    overrides: Overrides,
    /// Print diagnostics every N steps (0: summary only; default: the scene's
    /// `output.diagnostics_every`, else about 20 rows).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::whole::<usize>("0 or more"))]
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
    #[arg(
        long,
        value_name = "N",
        requires = "out",
        allow_hyphen_values = true,
        value_parser = crate::whole::<usize>("0 or more")
    )]
    out_every: Option<usize>,
    /// With --out: replace the files of an earlier run in DIR (frames, particles.pvd,
    /// summary.json, the CSV and SVG files a run writes). Without it a DIR that is not
    /// empty is refused; a DIR holding other files is refused even with it.
    #[arg(long, requires = "out")]
    overwrite: bool,
    /// With --out: encoding of the .vtu files: binary (zlib-compressed, the default)
    /// or ascii (text).
    #[arg(long, value_enum, value_name = "ENCODING", default_value_t = Vtu::Binary, requires = "out")]
    vtu: Vtu,
    /// With --out: the field particles.svg colours the particles by (first, middle
    /// and last frame): displacement (|u|), speed (|v|), sigma-xx, sigma-yy,
    /// sigma-xy, pressure (−tr σ / d) or von-mises (|σ_xx| in 1D, the uniaxial stress).
    #[arg(
        long,
        value_name = "FIELD",
        default_value = "displacement",
        requires = "out"
    )]
    picture: String,
    /// Threads of the particle phases (default: all cores). The results are the
    /// same, bit for bit, for any number.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = crate::whole::<usize>(crate::THREADS_RANGE))]
    threads: Option<usize>,
}

/// `--vtu`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Vtu {
    /// Binary: zlib-compressed, base64-encoded (small, fast to read).
    Binary,
    /// Text, one value per point and component.
    Ascii,
}

impl From<Vtu> for VtuEncoding {
    fn from(vtu: Vtu) -> VtuEncoding {
        match vtu {
            Vtu::Binary => VtuEncoding::Binary,
            Vtu::Ascii => VtuEncoding::Ascii,
        }
    }
}

/// Parses `AxB`. A single whole number (a 1D scene's count, say) is told the
/// pair it likely means.
pub fn pair(text: &str, what: &str) -> Result<(usize, usize), CliError> {
    let bad = || {
        let hint = match text.trim().parse::<usize>() {
            Ok(n) => format!(" (for {n} along x alone, as in a 1D scene: `{n}x1`)"),
            Err(_) => String::new(),
        };
        CliError::Input(format!(
            "{what} must look like 4x1, got `{}`{hint}",
            echo(text)
        ))
    };
    let (a, b) = text.split_once('x').ok_or_else(bad)?;
    Ok((a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?))
}

/// A set-up error of a scene file, located in the file when it names a field.
pub fn locate(scene: &str, e: &SceneError) -> String {
    if !scene.ends_with(".toml") {
        return e.to_string();
    }
    match std::fs::read_to_string(scene) {
        Ok(text) => e.in_file(&text, scene).to_string(),
        Err(_) => e.to_string(),
    }
}

/// A run that could not be set up, as the user sees it: a scene error named by the
/// command-line flags that set its field, else located in the scene file `scene`
/// when it is one.
pub fn run_error(scene: &str, overrides: &Overrides, e: RunError) -> CliError {
    match e {
        RunError::Scene(e) => {
            let flags = overrides.flags_of(&e);
            if flags.is_empty() {
                CliError::Input(locate(scene, &e))
            } else {
                CliError::Input(format!("{} with {}: {e}", echo(scene), flags.join(" ")))
            }
        }
        other => CliError::Input(other.to_string()),
    }
}

/// Reads a scene: a built-in name or a `.toml` file (relative Gmsh paths in it, of
/// the mesh and of bodies, are taken relative to the file).
pub fn read_scene(name: &str) -> Result<Scene, CliError> {
    if name.ends_with(".toml") {
        use psmpm::scene::limits::{echo, read_bounded, MAX_SCENE_FILE_BYTES};
        let bytes = read_bounded(std::path::Path::new(name), MAX_SCENE_FILE_BYTES)
            .map_err(|e| CliError::Input(format!("{}: {e}", echo(name))))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            // Where the first byte that is not UTF-8 stands, as a line and column.
            let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
            let line = 1 + valid.iter().filter(|&&b| b == b'\n').count();
            let start = valid.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
            let column = 1 + String::from_utf8_lossy(&valid[start..]).chars().count();
            CliError::Input(format!(
                "{}:{line}:{column}: cannot read: byte 0x{:02x} is not UTF-8; save the scene as UTF-8 text",
                echo(name),
                e.as_bytes()[valid.len()]
            ))
        })?;
        let mut s = Scene::from_toml(&text, name).map_err(|e| CliError::Input(e.to_string()))?;
        if let Some(dir) = std::path::Path::new(name).parent() {
            s.resolve_paths(dir);
        }
        Ok(s)
    } else {
        Scene::builtin(name).map_err(|unknown| {
            // A path that is not a `.toml` file: say so rather than list the
            // built-in scenes only.
            let path = std::path::Path::new(name);
            if path.is_dir() {
                CliError::Input(format!(
                    "{}: is a directory; give a scene file FILE.toml or a built-in scene",
                    psmpm::scene::limits::echo(name)
                ))
            } else if path.exists() {
                CliError::Input(format!(
                    "{}: a scene file must end in `.toml`",
                    psmpm::scene::limits::echo(name)
                ))
            } else if name.contains(['/', '\\']) || path.extension().is_some() {
                // A path to a file that is not there, not a scene's name.
                let known = unknown.split_once(" (known: ").map_or("", |(_, k)| k);
                CliError::Input(format!(
                    "{}: no such file; give a scene file FILE.toml or a built-in scene (known: {known}",
                    psmpm::scene::limits::echo(name)
                ))
            } else if std::path::Path::new(&format!("{name}.toml")).is_file() {
                // The scene file's name without its extension (`run drop`).
                CliError::Input(format!(
                    "{unknown}; a scene file `{}.toml` is here: give the file's whole name",
                    psmpm::scene::limits::echo(name)
                ))
            } else {
                CliError::Input(unknown)
            }
        })
    }
}

/// The basis `--basis NAME` gives a scene of dimension `dim`; the error names the
/// option, the scene's dimension and the bases that fit it.
pub fn basis_option(name: &str, dim: usize) -> Result<BasisKind, CliError> {
    let basis = BasisKind::parse(name).map_err(|m| {
        // Several bases side by side are `compare`'s (`run --basis ps,pl`).
        let side_by_side = if name.contains(',') {
            "; `run` takes one basis: to run several side by side, `mpm-cli compare SCENE --basis ps,pl`"
        } else {
            ""
        };
        CliError::Input(format!("--basis: {m}{side_by_side}"))
    })?;
    if basis.dim() != dim {
        let fit: Vec<&str> = BasisKind::ALL
            .into_iter()
            .filter(|k| k.dim() == dim)
            .map(BasisKind::name)
            .collect();
        return Err(CliError::Input(format!(
            "--basis {0}: `{0}` is a {1}D basis but the scene is {dim}D; give a {dim}D basis: {2}",
            basis.name(),
            basis.dim(),
            fit.join(" or ")
        )));
    }
    Ok(basis)
}

/// The scene of `run` with the command line's choices applied, validated.
fn scene(args: &RunArgs) -> Result<Scene, CliError> {
    let mut s = read_scene(&args.scene)?;
    if let Some(b) = &args.basis {
        s.basis = basis_option(b, s.dim)?;
    }
    if let Some(m) = &args.mass {
        s.mass = MassKind::parse(m).map_err(|m| CliError::Input(format!("--mass: {m}")))?;
    }
    args.overrides.apply(s, &args.scene)
}

/// A diagnostics row of `--format json`: the columns of `diagnostics.csv` as keys.
fn row_json(r: &StepReport) -> serde_json::Value {
    let worst = r.mass_report.worst_coverage;
    let at = |k: usize| r.worst_coverage_at.filter(|_| k < r.dim).map(|x| x[k]);
    // The values of `out::diagnostics_record`, in the order of its columns: the
    // keys are the CSV header's, numbers as numbers, `null` for an empty field.
    let values = [
        json!(r.step),
        json!(r.time),
        json!(r.kinetic),
        json!(r.strain),
        json!(r.potential),
        json!(r.work),
        json!(r.total_energy()),
        json!(r.total_centred),
        json!(r.mass),
        json!(r.momentum()[0]),
        // (0 in 1D, as in the CSV)
        json!(r.momentum().get(1).copied().unwrap_or(0.0)),
        json!(r.max_speed),
        json!(r.mass_report.active),
        json!(r.mass_report.lumped_rows),
        json!(r.mass_report.deactivated),
        json!(r.mass_report.extended),
        json!(worst.map(|(_, c)| c)),
        json!(worst.map(|(f, _)| f)),
        json!(at(0)),
        json!(at(1)),
        json!(r.condition),
        json!(r.kinetic_motion),
        json!(r.substeps),
        json!(out::critical_step(r)),
    ];
    serde_json::Value::Object(
        out::DIAGNOSTICS_COLUMNS
            .iter()
            .map(|k| k.to_string())
            .zip(values)
            .collect(),
    )
}

const COLUMNS: [&str; 12] = [
    "step",
    "time",
    "kinetic",
    "strain",
    "potential",
    "total",
    "max_speed",
    "active",
    "lumped",
    "extended",
    "min_cover",
    "condition",
];

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
        r.mass_report.extended.to_string(),
        r.mass_report
            .worst_coverage
            .map_or_else(|| "-".into(), |(_, c)| sci(c)),
        r.condition.map_or_else(|| "-".into(), sci),
    ]
}

/// Standard output of `run`: every line written and flushed at once; the first
/// error (the reader went away) closes it and asks the run to stop.
struct Stdout<'a> {
    out: std::io::StdoutLock<'static>,
    /// The error that closed it.
    error: Option<std::io::Error>,
    stop: &'a AtomicBool,
}

impl Stdout<'_> {
    fn print(&mut self, text: &str) {
        if self.error.is_some() {
            return;
        }
        if let Err(e) = self
            .out
            .write_all(text.as_bytes())
            .and_then(|()| self.out.flush())
        {
            self.error = Some(e);
            self.stop.store(true, Ordering::Relaxed);
        }
    }

    fn line(&mut self, text: &str) {
        self.print(&format!("{text}\n"));
    }

    /// The status of a closed stdout: quiet for a broken pipe.
    fn status(&mut self) -> Result<(), CliError> {
        match self.error.take() {
            None => Ok(()),
            Some(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Err(CliError::BrokenPipe),
            Some(e) => Err(CliError::Numerical(format!("standard output: {e}"))),
        }
    }
}

/// The stop flag of a run and its set-up flag. The first SIGINT or SIGTERM sets
/// the stop flag (the run finishes its step and ends), a second one exits at once
/// with status 130. While `setting_up` holds (until the observer sees step 0), the
/// first signal exits at once too, saying so: nothing has run, and the set-up of a
/// large mesh takes minutes (a user's 1000 × 1000 PS mesh for 36 particles) that a
/// stop after it would make the user wait out.
pub(crate) fn stop_on_signals() -> Result<(Arc<AtomicBool>, Arc<AtomicBool>), CliError> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    let stop = Arc::new(AtomicBool::new(false));
    let setting_up = Arc::new(AtomicBool::new(true));
    for signal in [SIGINT, SIGTERM] {
        let during_set_up = Arc::clone(&setting_up);
        // SAFETY: the action only reads an atomic and calls `write` and `_exit`,
        // both async-signal-safe; it allocates nothing and takes no lock.
        let set_up_action = move || {
            if during_set_up.load(Ordering::SeqCst) {
                const MESSAGE: &[u8] = b"interrupted during the set-up: nothing was run\n";
                unsafe {
                    libc::write(2, MESSAGE.as_ptr().cast(), MESSAGE.len());
                }
                signal_hook::low_level::exit(130);
            }
        };
        // Registered first, so that they see the flags as they were before this signal.
        unsafe { signal_hook::low_level::register(signal, set_up_action) }
            .and_then(|_| {
                signal_hook::flag::register_conditional_shutdown(signal, 130, Arc::clone(&stop))
            })
            .and_then(|_| signal_hook::flag::register(signal, Arc::clone(&stop)))
            .map_err(|e| CliError::Numerical(format!("cannot handle signals: {e}")))?;
    }
    Ok((stop, setting_up))
}

/// Runs the scene and prints diagnostics and the summary (and writes the files of
/// `--out`). JSON and CSV rows are printed as they are computed; the table is
/// aligned at the end. A closed stdout or a first SIGINT/SIGTERM stops the run after
/// the current step; the files of `--out` and the summary are still written.
pub fn run(args: RunArgs) -> Result<(), CliError> {
    let pool = thread_pool(args.threads)?;
    pool.install(move || run_on_pool(args))
}

/// `--threads N`: at least 1 and at most [`MAX_THREADS`].
pub fn check_threads(threads: Option<usize>) -> Result<(), CliError> {
    match threads {
        Some(0) => Err(CliError::Input("--threads must be at least 1".into())),
        Some(n) if n > MAX_THREADS => Err(CliError::Input(format!(
            "--threads {n} is above the limit of {MAX_THREADS}"
        ))),
        _ => Ok(()),
    }
}

/// The pool of `--threads N` (`None`: one thread per core).
pub fn thread_pool(threads: Option<usize>) -> Result<psmpm::threads::ThreadPool, CliError> {
    check_threads(threads)?;
    psmpm::threads::pool(threads).map_err(|e| {
        CliError::Input(format!(
            "--threads: no thread pool ({e}){}",
            if psmpm::threads::address_space_limited() {
                ": under this process's address-space limit (`ulimit -v`), each thread needs address space for its stack and up to 64 MB for its allocator; give fewer --threads, or a higher limit"
            } else {
                ""
            }
        ))
    })
}

/// The rows `run` prints: every this many steps (`--diag-every`, else the scene's
/// `output.diagnostics_every`, else about 20 rows; 0: none).
fn diag_every(s: &Scene, args: &RunArgs) -> usize {
    args.diag_every
        .unwrap_or(if s.output.diagnostics_every > 0 {
            s.output.diagnostics_every
        } else {
            (s.steps() / 20).max(1)
        })
}

/// The scene of `run` with every option applied and validated, and the sizes the
/// options control checked, before anything is created or run ([`crate::check`]).
pub fn prepare(args: &RunArgs) -> Result<Scene, CliError> {
    check_threads(args.threads)?;
    let mut s = scene(args)?;
    if args.out.is_some() {
        s.output.output_bytes_per_particle = out::bytes_per_particle(args.vtu.into());
    }
    check_sizes(&s, args, diag_every(&s, args))?;
    Ok(s)
}

/// [`run`] on the current thread pool.
fn run_on_pool(args: RunArgs) -> Result<(), CliError> {
    let s = prepare(&args)?;
    let mut every = diag_every(&s, &args);
    // A Courant-number scene knows its steps at the start of the run: the default
    // of about 20 rows is set then.
    let time_from_run = s.time.dt.is_none();
    let every_from_run =
        args.diag_every.is_none() && s.output.diagnostics_every == 0 && time_from_run;
    let mut too_many: Option<String> = None;
    let mut recorder = match &args.out {
        Some(dir) => {
            let options = out::OutOptions {
                every: args.out_every,
                overwrite: args.overwrite,
                encoding: args.vtu.into(),
                picture: ParticleField::parse(&args.picture, s.dim)
                    .map_err(|e| CliError::Input(format!("--picture: {e}")))?,
            };
            Some(Recorder::create(dir, options, &s)?)
        }
        None => None,
    };
    let (stop, setting_up) = stop_on_signals()?;
    let mut stdout = Stdout {
        out: std::io::stdout().lock(),
        error: None,
        stop: &stop,
    };
    let progress = Progress::new(s.steps() as u64, "steps");
    let t_end = s.time.t_end;
    let mut table = Table::new(&COLUMNS);
    let format = args.format;
    let mut csv_header = true;
    // When the steps began, and whether the run's length was told (once).
    let (mut stepping, mut told) = (None::<std::time::Instant>, false);
    let mut observer = |r: &StepReport, particles: ParticlesRef<'_>| {
        if let Some(recorder) = recorder.as_mut() {
            recorder.observe(r, particles);
            // A file that cannot be written (a full disk) ends the run at once:
            // the rest of it would be lost too.
            if recorder.failed() {
                stop.store(true, std::sync::atomic::Ordering::Relaxed);
                return;
            }
        }
        if r.step == 0 {
            // Set up: a signal from now on finishes the step and writes the files.
            setting_up.store(false, Ordering::SeqCst);
            if every_from_run && r.dt > 0.0 {
                every = (out::steps_from_dt(t_end, r.dt) / 20).max(1);
            }
            // A Courant-number scene's table is bounded now that its steps are
            // known: too many rows stop the run before its first step.
            if time_from_run && r.dt > 0.0 {
                too_many = too_many_rows(format, every, out::steps_from_dt(t_end, r.dt));
                if too_many.is_some() {
                    stop.store(true, std::sync::atomic::Ordering::Relaxed);
                    return;
                }
            }
            // The time step against the critical one, before the first step, and
            // what a run of very many steps owes them to.
            let mut line = time_step_line(r);
            if let Some(note) = long_run_note(&s, out::steps_from_dt(t_end, r.dt), r.dt) {
                line = format!("{line}\nnote: {note}");
            }
            match format {
                Format::Table => stdout.line(&line),
                Format::Json => {
                    for part in line.lines() {
                        let _ = writeln!(std::io::stderr(), "# {part}");
                    }
                }
                // stderr of csv holds `# key=value` lines only (the summary's dt and
                // dt_critical come at the end). The ratio of the step taken to the
                // critical one, before the first step: not `courant`, which the
                // summary gives as asked (the step taken is shortened to divide
                // the end time).
                Format::Csv => {
                    if let Some(c) = r.dt_critical.filter(|c| c.is_finite() && *c > 0.0) {
                        let _ = writeln!(std::io::stderr(), "# dt_over_critical={}", r.dt / c);
                    }
                }
            }
            return;
        }
        if r.step == 1 && r.time > 0.0 {
            progress.set_total(out::steps_from_dt(t_end, r.time) as u64);
        }
        progress.inc(1);
        // A long run says how long, once its first seconds tell (a student's
        // mesh of a million triangles ran 70 of its 41 000 steps in 5 minutes,
        // with no bar where stderr is not a terminal).
        let started = *stepping.get_or_insert_with(std::time::Instant::now);
        if !told && format == Format::Table && r.step > 1 {
            let seconds = started.elapsed().as_secs_f64();
            if seconds >= LENGTH_NOTE_AFTER {
                told = true;
                let total = out::steps_from_dt(t_end, r.dt);
                if let Some(note) = run_length_note(r.step - 1, seconds, total) {
                    let _ = writeln!(std::io::stderr(), "note: {note}");
                }
            }
        }
        if every > 0 && r.step % every == 0 {
            match format {
                Format::Json => stdout.line(&row_json(r).to_string()),
                Format::Csv => {
                    if std::mem::take(&mut csv_header) {
                        stdout.line(&out::csv_record(&out::DIAGNOSTICS_COLUMNS));
                    }
                    stdout.line(&out::csv_record(&out::diagnostics_record(r)));
                }
                Format::Table => table.push(row_cells(r)),
            }
        }
    };
    let outcome = match s.dim {
        2 => simulation::observe_2d_until(&s, &mut observer, &stop)
            .map(|o| (o.summary, o.tracked, Last::Two(o.particles))),
        _ => simulation::observe_1d_until(&s, &mut observer, &stop)
            .map(|o| (o.summary, o.tracked, Last::One(o.particles))),
    };
    progress.finish();
    // Bad input found at set-up (or too many rows): nothing was run, so nothing
    // stays in --out.
    let checked = match (outcome, too_many) {
        (Ok(o), None) => Ok(o),
        (Err(e), _) => Err(run_error(&args.scene, &args.overrides, e)),
        (Ok(_), Some(message)) => Err(CliError::Input(message)),
    };
    let (mut summary, tracked, last) = match checked {
        Ok(o) => o,
        Err(error) => {
            if let Some(recorder) = recorder {
                recorder.discard();
            }
            return Err(error);
        }
    };
    for warning in &summary.warnings {
        eprintln!("warning: {warning}");
    }
    // A file that could not be written stopped the run (not a signal).
    if summary.interrupted && recorder.as_ref().is_some_and(|r| r.failed()) {
        summary.interrupted = false;
        summary.failure = Some(format!(
            "after step {} (t = {}): an output file could not be written (the error follows)",
            summary.steps,
            short(summary.t_end)
        ));
    }
    let written = recorder.map(|r| {
        let dir = r.path().to_path_buf();
        r.finish(&summary, &tracked, last.view())
            .map(|files| out::files_line(&dir, &files))
    });
    match format {
        Format::Json => stdout.line(&summary_json(&summary).to_string()),
        // stdout stays CSV: the summary goes to stderr as `# key=value` lines. No
        // row was due (`--diag-every 0`, or above the steps): the header alone, so
        // that stdout is a CSV file a script can read (it was empty).
        Format::Csv => {
            if csv_header {
                stdout.line(&out::csv_record(&out::DIAGNOSTICS_COLUMNS));
            }
            eprint!("{}", summary_comments(&summary))
        }
        Format::Table => {
            if every > 0 {
                stdout.line(&table.render());
            }
            stdout.print(&summary_text(&summary));
        }
    }
    if let Some(written) = written {
        let line = written?;
        // stdout stays machine-readable for --format json and csv.
        match format {
            Format::Table => stdout.line(&line),
            Format::Json | Format::Csv => {
                let _ = writeln!(std::io::stderr(), "{line}");
            }
        }
    }
    stdout.status()?;
    if summary.interrupted {
        return Err(CliError::Interrupted);
    }
    match &summary.failure {
        Some(reason) => Err(CliError::Numerical(reason.clone())),
        None if !summary.stable => Err(CliError::Numerical(format!(
            "the run is UNSTABLE: {}",
            unstable_reason(&summary)
        ))),
        None => Ok(()),
    }
}

/// Steps from which a run says at the start how many it takes and why.
pub const LONG_RUN_STEPS: usize = 1_000_000;

/// Seconds of steps after which a run tells how long it will take
/// ([`run_length_note`]).
pub const LENGTH_NOTE_AFTER: f64 = 2.0;

/// A run whose steps take longer than this in all is told its length.
pub const LONG_RUN_SECONDS: f64 = 60.0;

/// The note of a run that `done` steps in `seconds` project beyond
/// [`LONG_RUN_SECONDS`] over its `total` steps: the time left and the ways to
/// a shorter first look.
pub fn run_length_note(done: usize, seconds: f64, total: usize) -> Option<String> {
    if done == 0 || total <= done {
        return None;
    }
    let per_step = seconds / done as f64;
    let left = per_step * (total - done) as f64;
    (seconds + left > LONG_RUN_SECONDS).then(|| {
        format!(
            "{done} of {total} steps in {seconds:.1} s ({} per step): about {} to go; for a first look lower `t_end` (`--t-end`) or coarsen the mesh; Ctrl-C stops the run and writes its files",
            duration(per_step),
            duration(left)
        )
    })
}

/// `seconds` as a person reads it: ms, s, min or h.
fn duration(seconds: f64) -> String {
    if seconds < 1.0 {
        let ms = format!("{:.3}", 1e3 * seconds);
        format!("{} ms", ms.trim_end_matches('0').trim_end_matches('.'))
    } else if seconds < 10.0 {
        format!("{seconds:.1} s")
    } else if seconds < 120.0 {
        format!("{seconds:.0} s")
    } else if seconds < 7200.0 {
        format!("{:.0} min", seconds / 60.0)
    } else {
        format!("{:.1} h", seconds / 3600.0)
    }
}

/// For a run of [`LONG_RUN_STEPS`] steps or more, how many and why: the critical
/// step is the element size over the P-wave speed, `√((λ + 2μ)/ρ)`, which a
/// Poisson's ratio near 1/2 makes large (a user's ν = 0.4999999999 gave 5·10⁶
/// steps, eight minutes, with nothing said at the start).
pub fn long_run_note(scene: &psmpm::scene::Scene, steps: usize, dt: f64) -> Option<String> {
    (steps >= LONG_RUN_STEPS).then(|| {
        // The P-wave speed over √(E / ρ), `√((λ + 2μ) / E)`, as the wave speed of
        // the scene takes it.
        let p_wave = |nu: f64| {
            let elastic = psmpm::material::Elastic {
                young: 1.0,
                poisson: nu,
                density: 1.0,
            };
            elastic.p_modulus(scene.dim).sqrt()
        };
        let nu = (0..scene.bodies.len().max(1))
            .map(|b| scene.body_material(b).poisson)
            .fold(f64::NEG_INFINITY, f64::max);
        let cause = if p_wave(nu) > 2.0 * p_wave(0.3) {
            format!(
                ": the step is the element size over the P-wave speed, which ν = {} makes {}× that of ν = 0.3 (nearly incompressible)",
                psmpm::scene::limits::echo_significant(nu, 12),
                psmpm::scene::limits::echo_significant(p_wave(nu) / p_wave(0.3), 3)
            )
        } else {
            // The fastest material's wave speed, with the units to check (a
            // density in g/cm³ beside a modulus in Pa runs 30 times too fast).
            format!(
                ": the step is the element size over the P-wave speed √((λ + 2μ) / ρ), {} here; if that is far above your material's speed of sound (in SI about 6e3 m/s for steel, 50 for rubber), check the units of `young` and `density`",
                sci(scene.wave_speed())
            )
        };
        format!(
            "this run takes {steps} steps of {}{cause}; for a first look lower `t_end` (`--t-end`) or coarsen the mesh",
            sci(dt)
        )
    })
}

/// `critical step watched as the bodies moved: …`, when the watch over the critical
/// step split steps of a run with `courant` (with a fixed `dt` a warning says it).
pub fn watched_line(summary: &Summary) -> Option<String> {
    let (lowest, start, c) = (
        summary.dt_critical_lowest?,
        summary.dt_critical?,
        summary.courant?,
    );
    if summary.split_steps == 0 {
        // Fell below the step itself, at the step that then stopped the run
        // (too far to split it): the stop message says so.
        if summary.failure.is_some() && lowest < summary.dt {
            return None;
        }
        // Fell, but not far enough to split a step: said, so that the figure in
        // summary.json is not the only trace.
        return (lowest < 0.9 * start).then(|| {
            format!(
                "critical step watched as the bodies moved: it fell to {} ({:.2} of the start's {}), not far enough to split a step at courant {}",
                sci(lowest),
                lowest / start,
                sci(start),
                short(c)
            )
        });
    }
    Some(format!(
        "critical step watched as the bodies moved: it fell to {} ({:.2} of the start's {}), so {} of the {} steps {} taken in up to {} sub-steps to keep courant {}",
        sci(lowest),
        lowest / start,
        sci(start),
        summary.split_steps,
        summary.steps,
        if summary.split_steps == 1 { "was" } else { "were" },
        summary.most_substeps,
        short(c)
    ))
}

/// `steps split for the particles' speeds: …`, when the watch split steps further
/// than the critical step needs, so that no particle crossed more than half its
/// element's width (or a quarter of its contact distance near a contact wall) in
/// one sub-step.
pub fn advected_line(summary: &Summary) -> Option<String> {
    if summary.advected_steps == 0 {
        return None;
    }
    Some(format!(
        "steps split for the particles' speeds: {} of the {} steps {} taken in up to {} sub-steps (speeds up to {}) so that no particle crossed more than {} of its element's width, or {} of its contact distance near a contact wall, in one sub-step",
        summary.advected_steps,
        summary.steps,
        if summary.advected_steps == 1 { "was" } else { "were" },
        summary.most_substeps,
        summary.fastest_speed.map_or("-".into(), sci),
        psmpm::driver::ADVECTION_SHARE,
        psmpm::driver::CONTACT_SHARE,
    ))
}

/// `time step … · critical step … · Courant number …`, printed at the start of a run.
pub fn time_step_line(r: &StepReport) -> String {
    match r.dt_critical {
        Some(c) if c.is_finite() && c > 0.0 => format!(
            "time step {} · critical step {} (estimated for this mesh, basis, mass strategy \
             and material) · Courant number {:.3}",
            sci(r.dt),
            sci(c),
            r.dt / c
        ),
        Some(_) => format!(
            "time step {} · no critical step (nothing stiff moves: no particle or no \
             stiffness)",
            sci(r.dt)
        ),
        None => format!(
            "time step {} · critical step not estimated (the mass system could not be \
             solved at the start: see the warning below)",
            sci(r.dt)
        ),
    }
}

/// Which bound of the verdict an unstable run that did not fail broke (with the
/// energy growth's hint).
pub fn unstable_reason(summary: &Summary) -> String {
    match summary.max_condition {
        Some(c) if c >= simulation::STABLE_CONDITION => format!(
            "condition estimate {} ≥ {}: {}",
            sci(c),
            sci(simulation::STABLE_CONDITION),
            simulation::condition_hint(&summary.mass)
        ),
        _ => {
            let mut reason = format!(
                "energy growth {:.2e} of the energy scale ≥ {} (time-centred total; the total itself grew {:.2e})",
                summary.energy_growth_centred,
                simulation::STABLE_ENERGY_GROWTH,
                summary.energy_growth
            );
            if let Some(hint) = &summary.energy_growth_hint {
                reason.push_str(": ");
                reason.push_str(hint);
            }
            reason
        }
    }
}

/// The sizes `run`'s options control, checked before the run: frames of `--out`
/// and rows of the table (the scene's own limits are checked by its validation).
fn check_sizes(s: &Scene, args: &RunArgs, every: usize) -> Result<(), CliError> {
    let steps = s.steps();
    if s.time.dt.is_none() {
        // Courant-number scenes know their steps only at the start of the run
        // (the recorder checks the frames then).
        return Ok(());
    }
    if let (Some(_), Some(n)) = (&args.out, args.out_every) {
        let frames = steps.checked_div(n).unwrap_or(0) + 2;
        if frames > MAX_FRAMES {
            return Err(CliError::Input(format!(
                "--out-every {n}: {steps} steps give {frames} particle frames, above the limit of {MAX_FRAMES}"
            )));
        }
    }
    match too_many_rows(args.format, every, steps) {
        Some(message) => Err(CliError::Input(message)),
        None => Ok(()),
    }
}

/// The error of a table of more than [`MAX_TABLE_ROWS`] rows (`every` steps a row
/// over `steps`), which is kept in memory until the end of the run.
fn too_many_rows(format: Format, every: usize, steps: usize) -> Option<String> {
    (format == Format::Table && every > 0 && steps / every > MAX_TABLE_ROWS).then(|| {
        format!(
            "--diag-every {every}: {steps} steps give {} table rows, above the limit of {MAX_TABLE_ROWS}; use --format csv or json (which stream) or a larger --diag-every",
            steps / every
        )
    })
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

/// The summary as `# key=value` lines, one per key of [`summary_json`] in its order
/// (strings bare, `null` as an empty value, numbers as JSON writes them).
pub fn summary_comments(summary: &Summary) -> String {
    let mut out = String::new();
    if let serde_json::Value::Object(map) = summary_json(summary) {
        for (key, value) in map {
            let value = match value {
                serde_json::Value::String(s) => s,
                serde_json::Value::Null => String::new(),
                other => other.to_string(),
            };
            out += &format!("# {key}={value}\n");
        }
    }
    out
}

/// The summary for reading at a glance.
pub fn summary_text(summary: &Summary) -> String {
    let mut out = String::new();
    out += &format!(
        "{} · {} · {} mass · {} · {} · {} of {} to t = {}\n",
        summary.scene,
        summary.basis,
        summary.mass,
        plural(summary.functions, "function", "functions"),
        plural(summary.particles, "particle", "particles"),
        plural(summary.steps, "step", "steps"),
        sci(summary.dt),
        // Six digits: a run that stopped early ends at a step's time, whose last
        // digits are noise (1.148648649).
        short(psmpm::scene::limits::significant(summary.t_end, 6))
    );
    let error = match (summary.error, summary.error_measure) {
        (Some(e), Some(m)) => format!("error {m} = {}", sci(e)),
        _ => "no reference solution".into(),
    };
    let stray = if summary.stray[1] > summary.stray[0] {
        format!(
            "; {} stray at the end",
            plural(summary.stray[1], "particle", "particles")
        )
    } else {
        String::new()
    };
    let came_apart = format!(
        "stable in energy, but a body came apart ({} at the start, {} at the end{stray}): see the warnings",
        plural(summary.pieces[0], "piece", "pieces"),
        summary.pieces[1]
    );
    out += &format!(
        "{error} · {} · energy {} → {} (drift {:.2e}) · max condition {} · lumped rows ≤ {}\n",
        if summary.failure.is_some() {
            // Stopped: the line after says why; no energy verdict is made.
            "FAILED"
        } else if summary.stable && summary.came_apart() {
            // The energy verdict does not see a body broken up (the warnings say
            // how): said on the verdict's own line.
            &came_apart
        } else if summary.stable && summary.held_by_deactivation {
            // Likewise bodies held by deactivated functions.
            "stable in energy, but deactivated functions held the bodies as a wall would: see the warnings"
        } else if summary.stable && summary.max_condition.is_none() {
            "stable (energy; condition not measured, see --condition)"
        } else if summary.stable {
            "stable"
        } else {
            "UNSTABLE"
        },
        sci(summary.energy_initial),
        sci(summary.energy_final),
        summary.energy_drift,
        summary.max_condition.map_or("-".into(), sci),
        summary.max_lumped_rows,
    );
    if let Some(line) = watched_line(summary) {
        out += &format!("{line}\n");
    }
    if let Some(line) = advected_line(summary) {
        out += &format!("{line}\n");
    }
    if let Some(reason) = &summary.failure {
        out += &format!("stopped: {reason}\n");
    }
    if summary.interrupted {
        out += &format!(
            "interrupted after step {} (t = {}): the summary covers the steps taken\n",
            summary.steps,
            short(summary.t_end)
        );
    }
    let p = &summary.phases;
    let total = (p.evaluate + p.assemble + p.solve + p.update).max(f64::MIN_POSITIVE);
    if summary.steps == 0 {
        // No time per step to give (a run that stopped in its first step).
        out += &format!("wall time {:.2} s (no step completed)\n", summary.seconds);
        return out;
    }
    out += &format!(
        "wall time {:.2} s ({:.1} µs/step): evaluate {:.0} % · assemble {:.0} % · solve {:.0} % · update {:.0} %\n",
        summary.seconds,
        1e6 * summary.seconds / summary.steps as f64,
        100.0 * p.evaluate / total,
        100.0 * p.assemble / total,
        100.0 * p.solve / total,
        100.0 * p.update / total
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run of a million steps or more says so at the start, and names a Poisson's
    /// ratio near 1/2 as the cause (a user waited eight minutes for ν = 0.4999999999).
    #[test]
    fn a_long_run_is_announced_with_its_cause() {
        let scene = |poisson: f64| {
            psmpm::scene::Scene::from_toml(
                &format!("name = \"b\"\ndim = 2\nbasis = \"ps\"\n[mesh]\nkind = \"blocks\"\nx = [0.0, 1.0]\ny = [0.0, 1.0]\nblocks = [2, 2]\n[material]\nyoung = 1e4\npoisson = {poisson:?}\ndensity = 1.0\n[[body]]\nmin = [0.0, 0.0]\nmax = [1.0, 1.0]\nper_block = [2, 2]\n[time]\ncourant = 0.5\nt_end = 1.0\n"),
                "b.toml",
            )
            .unwrap()
        };
        assert!(long_run_note(&scene(0.3), LONG_RUN_STEPS - 1, 1e-6).is_none());
        let plain = long_run_note(&scene(0.3), 2_000_000, 1e-6).unwrap();
        assert!(plain.starts_with("this run takes 2000000 steps"), "{plain}");
        assert!(!plain.contains("incompressible"), "{plain}");
        let nearly = long_run_note(&scene(0.4999999999), 5_000_000, 1e-8).unwrap();
        assert!(
            nearly.contains("ν = 0.4999999999 makes 35200× that of ν = 0.3"),
            "{nearly}"
        );
    }

    /// A run projected beyond a minute is told its length once its first seconds
    /// are measured (a mesh of a million triangles: 70 of 41 000 steps in 300 s);
    /// a short one is not.
    #[test]
    fn a_long_run_is_told_its_length_from_its_first_steps() {
        assert!(run_length_note(100, 2.0, 2000).is_none(), "40 s in all");
        let note = run_length_note(5, 21.4, 41_000).unwrap();
        assert!(
            note.starts_with("5 of 41000 steps in 21.4 s (4.3 s per step): about 48.7 h to go;"),
            "{note}"
        );
        let note = run_length_note(700, 2.1, 588_295).unwrap();
        assert!(
            note.contains("(3 ms per step): about 29 min to go"),
            "{note}"
        );
        assert!(run_length_note(0, 2.0, 10).is_none());
        assert!(run_length_note(10, 2.0, 10).is_none());
    }
}
