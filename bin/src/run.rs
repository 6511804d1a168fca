//! `mpm-cli run`: run a built-in scene and print per-step diagnostics.

use crate::error::CliError;
use crate::table::{sci, Table};
use crate::Format;
use psmpm::bases::BasisKind;
use psmpm::basis::basis::powell_sabin::SplitPoint;
use psmpm::driver::StepReport;
use psmpm::scene::{self, Grid, MassKind, RunError, Scene};
use serde_json::json;

/// Arguments of `mpm-cli run`.
#[derive(Debug, clap::Args)]
pub struct RunArgs {
    /// Built-in scene (vibrating-bar, column-small, vibrating-bar-1d, column-small-1d)
    /// or a scene file FILE.toml; command-line options override the scene's values.
    scene: String,
    /// Basis: ps or pl (2D scenes), bspline or pl1d (1D scenes).
    #[arg(long)]
    basis: Option<String>,
    /// Mass strategy: consistent, lumped, partial (lump rows touching empty elements),
    /// partial:TAU (lump rows with M_ii < TAU·max M_jj), deactivate or deactivate:THRESHOLD.
    #[arg(long)]
    mass: Option<String>,
    /// Block grid NXxNY (1D: number of elements, e.g. 8x1).
    #[arg(long, value_name = "NXxNY")]
    blocks: Option<String>,
    /// Particles per block PXxPY (1D: per element, e.g. 4x1).
    #[arg(long, value_name = "PXxPY")]
    particles: Option<String>,
    /// PS split points: incentre (default) or centroid (the thesis' tables).
    #[arg(long)]
    split: Option<String>,
    /// Triangulation of the rectangle: blocks (4 triangles per block, default) or
    /// block-delaunay (Delaunay of block corners and centres, the thesis' tables).
    #[arg(long)]
    grid: Option<String>,
    /// Time step.
    #[arg(long)]
    dt: Option<f64>,
    /// End time.
    #[arg(long)]
    t_end: Option<f64>,
    /// Estimate the mass-matrix condition number every step (about 60 extra solves).
    #[arg(long)]
    condition: bool,
    /// Print diagnostics every N steps (0: summary only).
    #[arg(long, default_value_t = 100)]
    diag_every: usize,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    format: Format,
}

fn pair(text: &str, what: &str) -> Result<(usize, usize), CliError> {
    let bad = || CliError::Input(format!("{what} must look like 4x1, got `{text}`"));
    let (a, b) = text.split_once('x').ok_or_else(bad)?;
    Ok((a.parse().map_err(|_| bad())?, b.parse().map_err(|_| bad())?))
}

/// The scene with the command line's overrides applied.
fn scene(args: &RunArgs) -> Result<Scene, CliError> {
    let mut s = if args.scene.ends_with(".toml") {
        let text = std::fs::read_to_string(&args.scene)
            .map_err(|e| CliError::Input(format!("{}: cannot read: {e}", args.scene)))?;
        Scene::from_toml(&text, &args.scene).map_err(|e| CliError::Input(e.to_string()))?
    } else {
        Scene::builtin(&args.scene).map_err(CliError::Input)?
    };
    if let Some(b) = &args.basis {
        s.basis = BasisKind::parse(b).map_err(CliError::Input)?;
    } else if s.dim == 1 {
        s.basis = BasisKind::Bspline;
    }
    if let Some(m) = &args.mass {
        s.mass = MassKind::parse(m).map_err(CliError::Input)?;
    }
    if let Some(b) = &args.blocks {
        s.blocks = pair(b, "--blocks")?;
    }
    if let Some(p) = &args.particles {
        s.particles_per_block = pair(p, "--particles")?;
    }
    if let Some(split) = &args.split {
        s.split = match split.as_str() {
            "incentre" => SplitPoint::Incentre,
            "centroid" => SplitPoint::Centroid,
            other => {
                return Err(CliError::Input(format!(
                    "unknown split point `{other}` (known: incentre, centroid)"
                )))
            }
        };
    }
    if let Some(grid) = &args.grid {
        s.grid = match grid.as_str() {
            "blocks" => Grid::Blocks,
            "block-delaunay" => Grid::BlockDelaunay,
            other => {
                return Err(CliError::Input(format!(
                    "unknown grid `{other}` (known: blocks, block-delaunay)"
                )))
            }
        };
    }
    if let Some(dt) = args.dt {
        s.dt = dt;
    }
    if let Some(t) = args.t_end {
        s.t_end = t;
    }
    s.condition = args.condition;
    s.validate().map_err(CliError::Input)?;
    Ok(s)
}

fn row_json(r: &StepReport) -> serde_json::Value {
    json!({
        "step": r.step,
        "time": r.time,
        "kinetic": r.kinetic,
        "strain": r.strain,
        "potential": r.potential,
        "total": r.total_energy(),
        "mass": r.mass,
        "momentum": r.momentum,
        "max_speed": r.max_speed,
        "active": r.mass_report.active,
        "lumped_rows": r.mass_report.lumped_rows,
        "deactivated": r.mass_report.deactivated,
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

/// Runs the scene and prints diagnostics and the summary.
pub fn run(args: RunArgs) -> Result<(), CliError> {
    let s = scene(&args)?;
    let mut table = Table::new(&COLUMNS);
    let every = args.diag_every;
    let json_mode = args.format == Format::Json;
    let mut on_step = |r: &StepReport| {
        if every > 0 && r.step % every == 0 {
            if json_mode {
                println!("{}", row_json(r));
            } else {
                table.push(row_cells(r));
            }
        }
    };
    let summary = scene::run(&s, &mut on_step).map_err(|e| match e {
        RunError::Setup(m) => CliError::Input(m),
        RunError::Step(step) => CliError::Numerical(step.to_string()),
    })?;
    if json_mode {
        let value = serde_json::to_value(&summary).expect("summary serialises");
        println!("{value}");
    } else {
        if every > 0 {
            print!("{}", table.render());
            println!();
        }
        println!(
            "{} · {} · {} mass · {} functions · {} particles · {} steps to t = {}",
            summary.scene,
            summary.basis,
            summary.mass,
            summary.functions,
            summary.particles,
            summary.steps,
            summary.t_end
        );
        println!(
            "error E_u = {} · max condition {} · energy {} → {} (drift {:.2e}) · {} · {:.2} s ({:.1} µs/step)",
            summary.error.map_or("-".into(), sci),
            summary.max_condition.map_or("-".into(), sci),
            sci(summary.energy_initial),
            sci(summary.energy_final),
            summary.energy_drift,
            if summary.stable { "stable" } else { "UNSTABLE" },
            summary.seconds,
            1e6 * summary.seconds / summary.steps.max(1) as f64
        );
        let p = &summary.phases;
        let total = (p.evaluate + p.assemble + p.solve + p.update).max(f64::MIN_POSITIVE);
        println!(
            "phases: evaluate {:.0} % · assemble {:.0} % · solve {:.0} % · update {:.0} %",
            100.0 * p.evaluate / total,
            100.0 * p.assemble / total,
            100.0 * p.solve / total,
            100.0 * p.update / total
        );
    }
    Ok(())
}
