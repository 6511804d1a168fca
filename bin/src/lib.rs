//! `mpm-cli`: the command-line face of psmpm. The binary (`main.rs`) calls
//! [`main`]; [`check`] is the same command line parsed and validated without
//! running anything (what the `cli_args` fuzz target drives).
//!
//! Exit status: see [`error::EXIT_STATUS`] (0 success, 1 failed or unstable run,
//! 2 bad input, 130 interrupted, 141 closed standard output).

mod basis_cmd;
mod compare;
mod converge;
pub mod error;
pub mod memory;
mod out;
mod progress;
mod project;
mod reproduce;
mod run;
mod scenes;
mod stability;
mod table;
mod throughput;

use clap::{Parser, Subcommand, ValueEnum};
pub use error::CliError;
use psmpm::scene::Scene;
use std::ffi::OsString;
use std::process::ExitCode;

/// Material Point Method with Powell–Sabin spline bases on triangular grids.
#[derive(Debug, Parser)]
#[command(name = "mpm-cli", version, about, long_about = None, after_help = error::EXIT_STATUS)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

/// The value parser of a whole-number option. Numeric options take
/// `allow_hyphen_values` (clap's `allow_negative_numbers` misses `-1e-3`), so that
/// a leading minus is part of the value: `--threads -1` is then refused naming the
/// option and its range (`invalid value '-1' for '--threads <N>': must be a whole
/// number from 1 to 1024`), not taken for an option of its own with clap's tip to
/// write `-- -1`. `range` says which values the option takes; the command checks
/// the bounds of a value that parses.
pub(crate) fn whole<T>(
    range: &'static str,
) -> impl Fn(&str) -> Result<T, String> + Clone + Send + Sync + 'static
where
    T: std::str::FromStr + Clone + Send + Sync + 'static,
{
    move |text: &str| {
        text.parse::<T>()
            .map_err(|_| format!("must be a whole number {range}"))
    }
}

/// Parses a real number of a flag, refusing text that `f64` rounds to 0 or to
/// infinity while it names neither (`1e-400` was read as 0 and echoed `0.0`).
pub(crate) fn real(text: &str) -> Result<f64, String> {
    let x: f64 = text
        .trim()
        .parse()
        .map_err(|_| "must be a number".to_string())?;
    let digits = text.trim().split(['e', 'E']).next().unwrap_or("");
    if x == 0.0 && digits.chars().any(|c| ('1'..='9').contains(&c)) {
        return Err(
            "is below the smallest representable number (about 1e-308) and would be read as 0"
                .into(),
        );
    }
    if x.is_infinite() && !text.to_ascii_lowercase().contains("inf") {
        return Err("is beyond the largest representable number (about 1.8e308)".into());
    }
    Ok(x)
}

/// The range of `--threads`, as [`whole`] names it ([`MAX_THREADS`] the limit).
pub(crate) const THREADS_RANGE: &str = "from 1 to 1024";
const _: () = assert!(psmpm::scene::limits::MAX_THREADS == 1024);

/// Output format of a command.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Format {
    /// Aligned columns for reading.
    Table,
    /// JSON for scripts.
    Json,
    /// Comma-separated values.
    Csv,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// L² projection of f = sin(πx) sin(πy) onto the bases (seed benchmark B1).
    ///
    /// Projects f on the Delaunay triangulation of an n × n lattice of the unit
    /// square for each level (PS n = 3, 5, 9, 17, …; PL n = 5, 9, 17, 33, …) and
    /// prints the L² errors of f and ∂f/∂x with their observed orders. With
    /// --mesh, projects on that Gmsh mesh instead (one level).
    Project(project::ProjectArgs),
    /// Run a scene and print per-step diagnostics and a summary.
    ///
    /// SCENE is a built-in scene (`mpm-cli scenes` lists them) or a scene file
    /// FILE.toml (`mpm-cli scene show NAME` prints one to start from). Energies
    /// are per unit thickness. Exit status 1 if the run fails numerically or is
    /// judged UNSTABLE; 130 if interrupted (SIGINT/SIGTERM: the current step is
    /// finished and the files and summary are written; a second signal exits at once,
    /// as does the first during the set-up).
    /// With --format json or csv the rows are printed (and flushed) as they are
    /// computed; the table is aligned and printed at the end.
    #[command(after_help = error::EXIT_STATUS)]
    Run(run::RunArgs),
    /// List the built-in scenes, one line each.
    Scenes(scenes::ScenesArgs),
    /// Show a scene as a scene file.
    #[command(subcommand)]
    Scene(scenes::SceneCommand),
    /// Run a scene with several bases (and mass strategies) side by side.
    ///
    /// Each basis runs at the resolution the scene gives it (its `[[resolution]]`
    /// tables), so that the variants have about the same number of functions, as in
    /// the thesis' PS 42 against PL 38 functions. Variants run in parallel; the
    /// results equal those of running them one by one.
    #[command(after_help = error::EXIT_STATUS)]
    Compare(compare::CompareArgs),
    /// Refinement study: error, observed order and wall time per level and basis.
    ///
    /// Level l refines the scene's blocks by 2^l along the axes its `[study]` names
    /// (polygon meshes: edge length / 2^l). With --out, also writes the log-log
    /// error-vs-h and work-precision (error vs wall time) plots.
    #[command(after_help = error::EXIT_STATUS)]
    Converge(converge::ConvergeArgs),
    /// Reproduce the seeds' benchmarks B2–B5: tables (markdown) and SVG figures.
    ///
    /// The full studies take about 2 minutes on one core; --quick runs the coarse
    /// versions the test suite pins. The UL-FEM references of b3 and b5b are cached
    /// in $PSMPM_CACHE_DIR, else $XDG_CACHE_HOME/psmpm, else $HOME/.cache/psmpm (none
    /// if no variable is set). A run that fails or is unstable is part of a study
    /// (its table marks it); --strict makes it exit status 1.
    #[command(after_help = error::EXIT_STATUS)]
    Reproduce(reproduce::ReproduceArgs),
    /// Pictures of the bases: a mesh with its PS refinement and control triangles,
    /// or one basis function.
    #[command(subcommand)]
    Basis(basis_cmd::BasisCommand),
    /// The stability matrix: every case of scenes/stability with every mass strategy.
    ///
    /// Per case and strategy: stable or not (with the failure and its step, or the
    /// bound the verdict broke), the error against the case's reference (or the
    /// energy growth), the σ_yy roughness of the column cases (at the end time,
    /// and its RMS over 50 states of the run), the largest condition estimate,
    /// lumped rows and deactivated functions, and the wall time per step. Cases run in parallel; every column but the wall time is the same
    /// on any number of threads. See docs/stability.md.
    #[command(after_help = error::EXIT_STATUS)]
    Stability(stability::StabilityArgs),
    /// Particle-steps per second and heap bytes per particle, per variant and size.
    ///
    /// The B5a column refined to about N particles (8 × 8 per block, 16 per
    /// triangle), a few steps of each variant; prints the table and the exponent of
    /// the cost per step against the particle count. For measuring one's own
    /// machine; see docs/performance.md and docs/scaling.md.
    Throughput(throughput::ThroughputArgs),
}

/// The command line `std::env::args_os()` run: parses it (printing usage errors,
/// `--help` and `--version` as clap does), runs the command and reports its error
/// on stderr; the exit status follows [`error::EXIT_STATUS`].
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    if !matches!(cli.command, Command::Run(_)) {
        // Rust ignores SIGPIPE, so that a closed stdout would make `println!` panic:
        // the commands other than `run` (which stops itself, see run.rs) end quietly
        // by SIGPIPE as other Unix tools do.
        // SAFETY: setting a signal's disposition to the default before any thread
        // is started.
        unsafe {
            libc::signal(libc::SIGPIPE, libc::SIG_DFL);
        }
    }
    let result = match cli.command {
        Command::Project(args) => project::run(args),
        Command::Run(args) => run::run(args),
        Command::Scenes(args) => scenes::list(args),
        Command::Scene(command) => scenes::scene(command),
        Command::Compare(args) => compare::compare(args),
        Command::Converge(args) => converge::converge(args),
        Command::Reproduce(args) => reproduce::run(args),
        Command::Basis(command) => basis_cmd::basis(command),
        Command::Stability(args) => stability::stability(args),
        Command::Throughput(args) => throughput::throughput(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            if !e.quiet() {
                use std::io::Write as _;
                let _ = writeln!(std::io::stderr(), "error: {e}");
            }
            ExitCode::from(e.exit_code())
        }
    }
}

/// What [`check`] found a command line to be.
#[derive(Debug)]
pub enum Checked {
    /// `run`: the scene with every option applied and validated, the sizes the
    /// options control checked; what remains is to run it.
    Run(Box<Scene>),
    /// `compare` or `converge`: the variants or levels it would run, each validated.
    Scenes(Vec<Scene>),
    /// Any other command: its arguments parsed (their values are checked when it
    /// runs, which is not done here).
    Parsed,
}

/// Parses `args` (the first is the program name) with the command line's
/// definitions and validates them as the command would before running anything:
/// for `run` the scene (built-in or file), `--basis`, `--mass`, the overrides, the
/// limits on steps, frames and table rows, and `--threads`; for `compare` and
/// `converge` every variant or level. Nothing is run, written or printed. A usage
/// error (`--help` and `--version` included) is a [`CliError::Input`] with clap's
/// message.
pub fn check<I, T>(args: I) -> Result<Checked, CliError>
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    let cli = Cli::try_parse_from(args).map_err(|e| CliError::Input(e.to_string()))?;
    match cli.command {
        Command::Run(args) => run::prepare(&args).map(|s| Checked::Run(Box::new(s))),
        Command::Compare(args) => compare::prepare(&args).map(Checked::Scenes),
        Command::Converge(args) => converge::prepare(&args).map(Checked::Scenes),
        _ => Ok(Checked::Parsed),
    }
}

#[cfg(test)]
mod real_tests {
    /// Text that `f64` rounds to 0 or to infinity is refused unless it says so.
    #[test]
    fn reals_that_round_to_zero_or_infinity_are_refused() {
        assert_eq!(super::real("2.5e-3"), Ok(2.5e-3));
        assert_eq!(super::real("0"), Ok(0.0));
        assert_eq!(super::real("0.0e-500"), Ok(0.0));
        assert!(super::real("inf").is_ok_and(f64::is_infinite));
        assert!(super::real("1e-400").unwrap_err().contains("read as 0"));
        assert!(super::real("-3e999")
            .unwrap_err()
            .contains("beyond the largest"));
        assert_eq!(super::real("x"), Err("must be a number".into()));
    }
}
