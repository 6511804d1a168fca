//! `mpm-cli reproduce`: the seeds' benchmarks B2–B5 as studies, printed as the
//! markdown tables of `docs/results.md`, with their SVG figures.
//!
//! The UL-FEM reference runs of `b3` and `b5b` are cached in [`cache_dir`], chosen
//! here from the environment; the library takes the directory as an argument.

use crate::error::CliError;
use crate::Format;
use psmpm::output::chart::line_plot;
use psmpm::simulation::RunError;
use psmpm::studies::reproduction::{reproduce, Effort, STUDIES};
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
    /// Directory for the SVG figures.
    #[arg(long, default_value = "docs/figures")]
    out: PathBuf,
    /// Output format: table (markdown, as in docs/results.md), json (one object per
    /// study with its tables) or csv (one block per table).
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
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
    std::fs::create_dir_all(&args.out)
        .map_err(|e| CliError::Input(format!("{}: cannot create: {e}", args.out.display())))?;
    let effort = if args.quick {
        Effort::Quick
    } else {
        Effort::Full
    };
    let cache = cache_dir();
    for name in &names {
        let clock = std::time::Instant::now();
        let report = reproduce(name, effort, cache.as_deref())
            .map_err(|RunError::Setup(m)| CliError::Input(m))?;
        let mut files = Vec::new();
        for figure in &report.figures {
            let path = args.out.join(&figure.file);
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
                            "rows": t.rows,
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
                    })
                );
                continue;
            }
            Format::Csv => {
                for table in &report.tables {
                    println!("# {}: {}", report.benchmark, table.title);
                    println!("{}", table.columns.join(","));
                    for row in &table.rows {
                        let cells: Vec<String> = row
                            .iter()
                            .map(|c| format!("\"{}\"", c.replace('"', "\"\"")))
                            .collect();
                        println!("{}", cells.join(","));
                    }
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
        println!("\n({name}: {:.0} s)\n", clock.elapsed().as_secs_f64());
    }
    Ok(())
}
