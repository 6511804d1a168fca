//! `mpm-cli reproduce`: the seeds' benchmarks B2–B5 as studies, printed as the
//! markdown tables of `docs/results.md`, with their SVG figures written into
//! `--out DIR` (no figures without it: `--out docs/figures` regenerates those of the
//! write-up).
//!
//! `--format json` prints one object per study whose table cells are JSON values:
//! the unrounded number behind a number cell, `null` for `-`, booleans, integers,
//! and text otherwise. `--format csv` prints one block per table (a `# study: title`
//! line, the header, the rows as shown), quoted as RFC 4180 needs.
//!
//! The UL-FEM reference runs of `b3` and `b5b` are cached in [`cache_dir`], chosen
//! here from the environment; the library takes the directory as an argument.

use crate::error::CliError;
use crate::Format;
use psmpm::output::chart::line_plot;
use psmpm::simulation::RunError;
use psmpm::studies::reproduction::{reproduce, Effort, STUDIES};
use std::io::Write;
use std::path::PathBuf;

/// The cache directory of the UL-FEM reference runs
/// ([`psmpm::studies::ulfem::cached_reference_history`]): `$PSMPM_CACHE_DIR` if set
/// (and non-empty), else `$XDG_CACHE_HOME/psmpm`, else `$HOME/.cache/psmpm` (never the
/// source tree); `None` (no cache) if none is set.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    var("PSMPM_CACHE_DIR")
        .map(PathBuf::from)
        .or_else(|| var("XDG_CACHE_HOME").map(|d| PathBuf::from(d).join("psmpm")))
        .or_else(|| var("HOME").map(|d| PathBuf::from(d).join(".cache").join("psmpm")))
}

/// Arguments of `mpm-cli reproduce`.
#[derive(Debug, clap::Args)]
pub struct ReproduceArgs {
    /// Studies: b2, b3, b4, b5b, b5c, or all.
    #[arg(value_delimiter = ',', default_value = "all")]
    studies: Vec<String>,
    /// Coarse grids and short runs (seconds; what the tests pin) instead of the full
    /// studies (minutes).
    #[arg(long)]
    quick: bool,
    /// Write the SVG figures into DIR (created if needed; none are written without
    /// it). `--out docs/figures` regenerates the figures of docs/results.md.
    #[arg(long, value_name = "DIR")]
    out: Option<PathBuf>,
    /// Output format: table (markdown, as in docs/results.md), json (one object per
    /// study with its tables) or csv (one block per table).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
    /// Exit with status 1 when a run of a study failed or is unstable (default: 0,
    /// the tables mark it).
    #[arg(long)]
    strict: bool,
}

/// Runs the studies and prints their tables.
pub fn run(args: ReproduceArgs) -> Result<(), CliError> {
    let names: Vec<String> = if args.studies.iter().any(|s| s == "all") {
        STUDIES.iter().map(|s| s.to_string()).collect()
    } else {
        args.studies.clone()
    };
    for name in &names {
        if !STUDIES.contains(&name.as_str()) {
            return Err(CliError::Input(format!(
                "unknown study `{}` (known: {}, all)",
                psmpm::scene::limits::echo(name),
                STUDIES.join(", ")
            )));
        }
    }
    if let Some(out) = &args.out {
        std::fs::create_dir_all(out)
            .map_err(|e| CliError::Input(format!("{}: cannot create: {e}", out.display())))?;
    }
    let effort = if args.quick {
        Effort::Quick
    } else {
        Effort::Full
    };
    let cache = cache_dir();
    let (mut runs, mut failed) = (0, 0);
    for name in &names {
        let clock = std::time::Instant::now();
        let report = reproduce(name, effort, cache.as_deref())
            .map_err(|e: RunError| CliError::Input(e.to_string()))?;
        runs += report.runs.total;
        failed += report.runs.failed;
        let mut files = Vec::new();
        for figure in args.out.iter().flat_map(|out| {
            report
                .figures
                .iter()
                .map(move |figure| (out.join(&figure.file), figure))
        }) {
            let (path, figure) = figure;
            line_plot(&path, &figure.plot)
                .map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
            files.push(path.display().to_string());
        }
        match args.format {
            Format::Json => {
                let tables: Vec<_> = report
                    .tables
                    .iter()
                    .map(|t| {
                        serde_json::json!({
                            "title": t.title,
                            "columns": t.columns,
                            "rows": t.rows.iter().map(|row| row.iter().map(|c| c.json()).collect::<Vec<_>>()).collect::<Vec<_>>(),
                        })
                    })
                    .collect();
                println!(
                    "{}",
                    serde_json::json!({
                        "study": report.benchmark,
                        "tables": tables,
                        "findings": report.findings,
                        "figures": files,
                        "runs": report.runs.total,
                        "failed_runs": report.runs.failed,
                    })
                );
                continue;
            }
            Format::Csv => {
                let stdout = std::io::stdout();
                let mut lock = stdout.lock();
                for table in &report.tables {
                    writeln!(lock, "# {}: {}", report.benchmark, table.title)
                        .map_err(|e| CliError::Input(format!("stdout: {e}")))?;
                    let mut w = csv::Writer::from_writer(&mut lock);
                    let rows = std::iter::once(table.columns.clone()).chain(
                        table
                            .rows
                            .iter()
                            .map(|row| row.iter().map(|c| c.text.as_str()).collect()),
                    );
                    for row in rows {
                        w.write_record(&row)
                            .map_err(|e| CliError::Input(format!("stdout: {e}")))?;
                    }
                    w.flush()
                        .map_err(|e| CliError::Input(format!("stdout: {e}")))?;
                }
                continue;
            }
            Format::Table => {}
        }
        println!("## {}\n", report.benchmark.to_uppercase());
        for table in &report.tables {
            println!("{}", table.markdown());
        }
        for finding in &report.findings {
            println!("- {finding}");
        }
        for file in &files {
            println!("- figure: `{file}`");
        }
        if report.runs.failed > 0 {
            println!(
                "- {} of {} runs failed or are unstable",
                report.runs.failed, report.runs.total
            );
        }
        println!("\n({name}: {:.0} s)\n", clock.elapsed().as_secs_f64());
    }
    crate::error::study_verdict(args.strict, failed, runs)
}
