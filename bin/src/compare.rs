//! `mpm-cli compare`: the same scene with several bases and mass strategies, side by
//! side, each basis at the resolution the scene gives it (`[[resolution]]`), so that
//! the variants have about the same number of functions.
//!
//! Variants run on separate threads (up to `--jobs`); each run is single-threaded and
//! deterministic, so the results are identical to running them one by one (only the
//! wall times differ, and they are measured under the contention of the parallel runs).

use crate::error::CliError;
use crate::run::{read_scene, summary_json, Overrides};
use crate::table::{sci, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::mass::MassKind;
use psmpm::scene::Scene;
use psmpm::simulation::{self, RunError, Summary};
use psmpm::threads::ThreadPool;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::Mutex;

/// Arguments of `mpm-cli compare`.
#[derive(Debug, clap::Args)]
pub struct CompareArgs {
    /// Built-in scene (see `mpm-cli scenes`) or a scene file FILE.toml.
    scene: String,
    /// Bases to compare, comma-separated (default: ps,pl in 2D, bspline,pl1d in 1D).
    #[arg(long, value_delimiter = ',')]
    basis: Vec<String>,
    /// Mass strategies to compare, comma-separated (default: the scene's).
    #[arg(long, value_delimiter = ',')]
    mass: Vec<String>,
    /// Variants run at the same time (default: the number of cores).
    #[arg(long, allow_hyphen_values = true, value_parser = crate::whole::<usize>("1 or more"))]
    jobs: Option<usize>,
    /// Threads of the particle phases, shared by the variants running at the same
    /// time (default: all cores). The results are the same for any number.
    #[arg(long, value_name = "N", allow_hyphen_values = true, value_parser = crate::whole::<usize>(crate::THREADS_RANGE))]
    threads: Option<usize>,
    #[command(flatten)]
    overrides: Overrides,
    /// Exit with status 1 when a variant failed or is unstable (default: 0, the
    /// table marks it).
    #[arg(long)]
    strict: bool,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

/// The variants of a comparison of the scene read from `file`, in output order.
pub fn variants(
    base: &Scene,
    bases: &[String],
    masses: &[String],
    overrides: &Overrides,
    file: &str,
) -> Result<Vec<Scene>, CliError> {
    let bases: Vec<BasisKind> = if bases.is_empty() {
        BasisKind::ALL
            .into_iter()
            .filter(|b| b.dim() == base.dim)
            .collect()
    } else {
        bases
            .iter()
            .map(|b| crate::run::basis_option(b, base.dim))
            .collect::<Result<_, _>>()?
    };
    let masses: Vec<MassKind> = if masses.is_empty() {
        vec![base.mass]
    } else {
        masses
            .iter()
            .map(|m| MassKind::parse(m).map_err(|e| CliError::Input(format!("--mass: {e}"))))
            .collect::<Result<_, _>>()?
    };
    // A variant listed twice would run twice and print two identical rows.
    if let Some(b) = listed_twice(&bases) {
        return Err(CliError::Input(format!(
            "--basis: `{}` is listed twice",
            b.name()
        )));
    }
    if let Some(m) = listed_twice(&masses) {
        return Err(CliError::Input(format!(
            "--mass: `{}` is listed twice",
            m.spec()
        )));
    }
    let mut out = Vec::new();
    for &b in &bases {
        let with_basis = base
            .with_basis(b)
            .map_err(|e| CliError::Input(format!("--basis {}: {e}", b.name())))?;
        for &m in &masses {
            let mut s = with_basis.clone();
            s.mass = m;
            out.push(overrides.apply(s, file)?);
        }
    }
    Ok(out)
}

/// The first entry of `list` that an earlier one equals.
fn listed_twice<T: PartialEq>(list: &[T]) -> Option<&T> {
    list.iter()
        .enumerate()
        .find_map(|(i, x)| list[..i].contains(x).then_some(x))
}

/// Runs `scenes`, up to `jobs` at the same time, their steps on `pool`; results in
/// the order of `scenes`, a set-up error as `describe` tells it (naming the
/// command-line flags that set its field: [`crate::run::run_error`]). Once `stop`
/// is set the runs stop after their step (their summaries say `interrupted`) and
/// no other starts: `None` for those.
pub fn run_all(
    scenes: &[Scene],
    jobs: usize,
    pool: &ThreadPool,
    stop: &AtomicBool,
    describe: impl Fn(RunError) -> CliError,
) -> Vec<Option<Result<Summary, CliError>>> {
    let next = AtomicUsize::new(0);
    let progress =
        crate::progress::Progress::new(scenes.iter().map(|s| s.steps() as u64).sum(), "steps");
    let results: Mutex<Vec<Option<Result<Summary, RunError>>>> =
        Mutex::new(vec![None; scenes.len()]);
    std::thread::scope(|scope| {
        for _ in 0..jobs.clamp(1, scenes.len().max(1)) {
            scope.spawn(|| loop {
                if stop.load(Ordering::SeqCst) {
                    break;
                }
                let k = next.fetch_add(1, Ordering::SeqCst);
                let Some(scene) = scenes.get(k) else { break };
                let r =
                    pool.install(|| simulation::run_until(scene, &mut |_| progress.inc(1), stop));
                if let Ok(mut all) = results.lock() {
                    all[k] = Some(r);
                }
            });
        }
    });
    progress.finish();
    results
        .into_inner()
        .unwrap_or_default()
        .into_iter()
        .map(|r| r.map(|r| r.map_err(&describe)))
        .collect()
}

const COLUMNS: [&str; 12] = [
    "basis",
    "mass",
    "functions",
    "particles",
    "dt",
    "steps",
    "error",
    "max_condition",
    "lumped_rows",
    "energy_drift",
    "stable",
    "seconds",
];

/// The columns `--format csv` adds after [`COLUMNS`]: the table's verdict, the
/// time each run reached (a stopped one stops early), the pieces the particles
/// form at the start and the end and the stray ones at the end (a body that came
/// apart), the first tracked particle's start and end displacement (`output.tracked`;
/// empty without one; `y` components 0 in 1D), and why a run stopped (empty when it
/// completed).
const CSV_COLUMNS: [&str; 10] = [
    "verdict",
    "t_end",
    "pieces_start",
    "pieces_end",
    "stray_end",
    "tracked_x0",
    "tracked_y0",
    "tracked_ux",
    "tracked_uy",
    "failure",
];

/// Whether `s` is a run of a 1D basis (its tracked particle has no y).
fn one_dimensional(s: &Summary) -> bool {
    psmpm::bases::BasisKind::parse(s.basis).is_ok_and(|b| b.dim() == 1)
}

/// The table's verdict on a run: `stopped` (it failed; the line below the table
/// says why), `yes, in pieces` (stable in energy, with a body broken up: the
/// warnings say how), `yes, held` (stable in energy, with bodies held by
/// deactivated functions: a student's falling block hung in mid-air under
/// `yes`), `yes` or `NO`.
fn verdict(s: &Summary) -> &'static str {
    match (s.stable, s.failure.is_some()) {
        (_, true) => "stopped",
        _ if s.interrupted => "interrupted",
        (true, false) if s.came_apart() => "yes, in pieces",
        (true, false) if s.held_by_deactivation => "yes, held",
        (true, false) => "yes",
        (false, false) => "NO",
    }
}

/// The variants of the comparison, validated, and `--jobs` and `--threads` checked
/// ([`crate::check`]).
pub fn prepare(args: &CompareArgs) -> Result<Vec<Scene>, CliError> {
    let base = read_scene(&args.scene)?;
    let scenes = variants(&base, &args.basis, &args.mass, &args.overrides, &args.scene)?;
    if args.jobs == Some(0) {
        return Err(CliError::Input("--jobs must be at least 1".into()));
    }
    crate::run::check_threads(args.threads)?;
    Ok(scenes)
}

/// Runs the comparison and prints it.
pub fn compare(args: CompareArgs) -> Result<(), CliError> {
    let scenes = prepare(&args)?;
    let jobs = args.jobs.unwrap_or_else(|| {
        std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)
    });
    let pool = crate::run::thread_pool(args.threads)?;
    // A first signal stops the runs after their step and prints the table of
    // what ran (a student's interrupted comparison printed nothing); a second
    // exits at once.
    let (stop, setting_up) = crate::run::stop_on_signals()?;
    setting_up.store(false, Ordering::SeqCst);
    let results = run_all(&scenes, jobs, &pool, &stop, |e| {
        crate::run::run_error(&args.scene, &args.overrides, e)
    });
    let interrupted = stop.load(Ordering::SeqCst);
    let mut summaries = Vec::new();
    for r in results.into_iter().flatten() {
        summaries.push(r?);
    }
    if interrupted {
        if !summaries.is_empty() {
            print_summaries(&summaries, args.format, args.jobs != Some(1));
        }
        let whole = summaries.iter().filter(|s| !s.interrupted).count();
        eprintln!(
            "interrupted: {whole} of the {} variants ran to their end, {} stopped early (`interrupted` in the table), {} not started",
            scenes.len(),
            summaries.len() - whole,
            scenes.len() - summaries.len()
        );
        return Err(CliError::Interrupted);
    }
    // What `run` warns about, per variant (on standard error, before the table);
    // a warning several variants give is printed once, naming them all (a user's
    // comparison of six mass strategies printed PL's lattice warning six times).
    let mut distinct: Vec<(&str, Vec<String>)> = Vec::new();
    for s in &summaries {
        for warning in &s.warnings {
            let variant = format!("{} {}", s.basis, s.mass);
            match distinct.iter_mut().find(|(w, _)| *w == warning.as_str()) {
                Some((_, variants)) => variants.push(variant),
                None => distinct.push((warning.as_str(), vec![variant])),
            }
        }
    }
    for (warning, variants) in &distinct {
        let who = if variants.len() > 1 && variants.len() == summaries.len() {
            "every variant".to_string()
        } else {
            variants.join(", ")
        };
        eprintln!("warning ({who}): {warning}");
    }
    // As asked: `--jobs 1` runs them one after the other.
    print_summaries(&summaries, args.format, args.jobs != Some(1));
    let failed = summaries.iter().filter(|s| !s.stable).count();
    crate::error::study_verdict(args.strict, failed, summaries.len())
}

/// Prints summaries side by side.
/// The displacement of the scene's first tracked particle (`output.tracked`) at
/// the end of each variant, so that variants without a reference solution are
/// compared on a physical result (a cantilever's tip deflection: PL's locking
/// shows as a smaller one). Nothing without tracked points.
fn print_tracked(summaries: &[Summary]) {
    let Some((x0, _)) = summaries.iter().find_map(|s| s.tracked_end.first()) else {
        return;
    };
    let one_d = summaries
        .first()
        .is_some_and(|s| matches!(s.basis, "bspline" | "pl1d"));
    let near = |x: f64| psmpm::scene::limits::echo_significant(x, 4);
    let point = |x: &[f64]| {
        if one_d {
            format!("x = {}", near(x[0]))
        } else {
            format!("({}, {})", near(x[0]), near(x[1]))
        }
    };
    // Variants whose lattices differ (`[[resolution]]`, `--particles`) track
    // different particles: each row then says which.
    let same = summaries
        .iter()
        .all(|s| s.tracked_end.first().is_none_or(|(x, _)| x == x0));
    let mut header = vec!["basis", "mass"];
    if !same {
        header.push("started at");
    }
    header.push("u_x");
    if !one_d {
        header.push("u_y");
    }
    header.push("at t");
    let mut table = Table::new(&header);
    for s in summaries {
        let first = s.tracked_end.first();
        let u = first.map(|(_, u)| *u);
        let mut row = vec![s.basis.to_string(), s.mass.clone()];
        if !same {
            row.push(first.map_or_else(|| "-".into(), |(x, _)| point(x)));
        }
        row.push(u.map_or_else(|| "-".into(), |u| sci(u[0])));
        if !one_d {
            row.push(u.map_or_else(|| "-".into(), |u| sci(u[1])));
        }
        row.push(crate::table::short(s.t_end));
        table.push(row);
    }
    if same {
        println!("displacement of the tracked particle that started at {}, at the end of each run (output.tracked; the histories: run --out, tracked.csv):", point(x0));
    } else {
        println!("displacement of each run's tracked particle, the one nearest the first tracked point (the variants' particles differ), at the end of each run (output.tracked; the histories: run --out, tracked.csv):");
    }
    print!("{}", table.render());
}

/// `side_by_side`: the variants ran at the same time (not `--jobs 1`), which the
/// table's note on the wall times says.
pub fn print_summaries(summaries: &[Summary], format: Format, side_by_side: bool) {
    match format {
        Format::Json => {
            let all: Vec<_> = summaries.iter().map(summary_json).collect();
            println!("{}", serde_json::Value::Array(all));
        }
        Format::Csv => {
            let header: Vec<&str> = COLUMNS.iter().chain(&CSV_COLUMNS).copied().collect();
            println!("{}", crate::out::csv_record(&header));
            let opt = |v: Option<f64>| v.map_or_else(String::new, |x| x.to_string());
            for s in summaries {
                let tracked = s.tracked_end.first();
                let tracked = |f: fn(&([f64; 2], [f64; 2])) -> f64| {
                    tracked.map_or_else(String::new, |t| f(t).to_string())
                };
                let record = [
                    s.basis.to_string(),
                    s.mass.clone(),
                    s.functions.to_string(),
                    s.particles.to_string(),
                    s.dt.to_string(),
                    s.steps.to_string(),
                    opt(s.error),
                    opt(s.max_condition),
                    s.max_lumped_rows.to_string(),
                    s.energy_drift.to_string(),
                    s.stable.to_string(),
                    s.seconds.to_string(),
                    verdict(s).to_string(),
                    s.t_end.to_string(),
                    s.pieces[0].to_string(),
                    s.pieces[1].to_string(),
                    s.stray[1].to_string(),
                    tracked(|t| t.0[0]),
                    // A 1D run has no y: empty, as without `output.tracked`.
                    if one_dimensional(s) {
                        String::new()
                    } else {
                        tracked(|t| t.0[1])
                    },
                    tracked(|t| t.1[0]),
                    if one_dimensional(s) {
                        String::new()
                    } else {
                        tracked(|t| t.1[1])
                    },
                    s.failure.clone().unwrap_or_default(),
                ];
                println!("{}", crate::out::csv_record(&record));
            }
        }
        Format::Table => {
            let mut table = Table::new(&COLUMNS);
            for s in summaries {
                table.push(vec![
                    s.basis.to_string(),
                    s.mass.clone(),
                    s.functions.to_string(),
                    s.particles.to_string(),
                    sci(s.dt),
                    s.steps.to_string(),
                    s.error.map_or_else(|| "-".into(), sci),
                    s.max_condition.map_or_else(|| "-".into(), sci),
                    s.max_lumped_rows.to_string(),
                    sci(s.energy_drift),
                    verdict(s).to_string(),
                    format!("{:.2}", s.seconds),
                ]);
            }
            print!("{}", table.render());
            if let Some(s) = summaries.first() {
                // The end time the completed variants reached (a stopped one's
                // time is where it stopped: listed after it).
                let t_end = summaries
                    .iter()
                    .filter(|v| v.failure.is_none())
                    .map(|v| v.t_end)
                    .fold(0.0, f64::max);
                let error = match s.error_measure {
                    Some(measure) => {
                        format!("error {measure} at the end (or where a run stopped)")
                    }
                    None => "no reference solution, no error".to_string(),
                };
                // Where a variant stopped early, its own time, to 3 digits.
                let stopped: Vec<String> = summaries
                    .iter()
                    .filter(|v| v.failure.is_some() || v.t_end < t_end)
                    .map(|v| {
                        format!(
                            "{} {} stopped at t = {}",
                            v.basis,
                            v.mass,
                            crate::table::short(
                                crate::table::sci(v.t_end).parse().unwrap_or(v.t_end)
                            )
                        )
                    })
                    .collect();
                let reached = if stopped.len() == summaries.len() {
                    format!("every variant stopped ({})", stopped.join("; "))
                } else if stopped.is_empty() {
                    format!("t = {}", crate::table::short(t_end))
                } else {
                    format!(
                        "t = {} ({})",
                        crate::table::short(t_end),
                        stopped.join("; ")
                    )
                };
                println!(
                    "{}: {error}, {reached}; wall times measured {}",
                    s.scene,
                    if side_by_side {
                        "side by side"
                    } else {
                        "one after the other (--jobs 1)"
                    }
                );
                print_tracked(summaries);
                let steps: Vec<f64> = summaries.iter().map(|s| s.dt).collect();
                if steps.iter().any(|&dt| dt != steps[0]) {
                    println!(
                        "the variants run at different time steps (`courant` sets each one's \
                         from its own critical step): give --dt to compare them at one step"
                    );
                }
                if summaries.iter().any(|s| s.stable && s.held_by_deactivation) {
                    println!(
                        "yes, held: stable in energy, but deactivated functions held particles at \
                         zero velocity, so the bodies hang from or rest on them as on a wall (the \
                         warning above): their motion is not the scene's"
                    );
                }
                if summaries.iter().any(|s| s.max_condition.is_none()) {
                    println!(
                        "stable: completed with a growth of the time-centred total energy under {} of the energy scale; the \
                         condition of the solved system enters the verdict only where it was \
                         measured (--condition: below {})",
                        simulation::STABLE_ENERGY_GROWTH,
                        sci(simulation::STABLE_CONDITION)
                    );
                }
            }
            for s in summaries {
                if let Some(line) = crate::run::watched_line(s) {
                    println!("{} {}: {line}", s.basis, s.mass);
                }
                if let Some(line) = crate::run::advected_line(s) {
                    println!("{} {}: {line}", s.basis, s.mass);
                }
                if let Some(reason) = &s.failure {
                    println!("{} {}: {reason}", s.basis, s.mass);
                } else if !s.stable {
                    println!(
                        "{} {}: UNSTABLE: {}",
                        s.basis,
                        s.mass,
                        crate::run::unstable_reason(s)
                    );
                }
            }
        }
    }
}
