//! `mpm-cli reproduce`: the seeds' benchmarks B2–B5 as studies, printed as the
//! markdown tables of `docs/results.md`, with their SVG figures.

use crate::error::CliError;
use psmpm::plot::line_plot;
use psmpm::reproduction::{reproduce, Effort, STUDIES};
use psmpm::simulation::RunError;
use std::path::PathBuf;

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
                "unknown study `{name}` (known: {}, all)",
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
    for name in &names {
        let clock = std::time::Instant::now();
        let report = reproduce(name, effort).map_err(|RunError::Setup(m)| CliError::Input(m))?;
        println!("## {}\n", report.benchmark.to_uppercase());
        for table in &report.tables {
            println!("{}", table.markdown());
        }
        for finding in &report.findings {
            println!("- {finding}");
        }
        for figure in &report.figures {
            let path = args.out.join(&figure.file);
            line_plot(&path, &figure.plot)
                .map_err(|e| CliError::Input(format!("{}: {e}", path.display())))?;
            println!("- figure: `{}`", path.display());
        }
        println!("\n({name}: {:.0} s)\n", clock.elapsed().as_secs_f64());
    }
    Ok(())
}
